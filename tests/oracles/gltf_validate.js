// Runs the Khronos glTF validator (npm `gltf-validator`, installed by `make deps` into
// .tools/node_modules) on one file and prints its JSON report on stdout.
// Usage: node tests/oracles/gltf_validate.js FILE.glb [MORE.glb ...] (one report a line)
'use strict';
const fs = require('fs');
const path = require('path');

const modules = process.env.TINSMITH_NODE_MODULES
  || path.join(__dirname, '..', '..', '.tools', 'node_modules');
const validator = require(path.join(modules, 'gltf-validator'));

(async () => {
  for (const file of process.argv.slice(2)) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 100 });
    process.stdout.write(JSON.stringify(report) + '\n');
  }
})().catch((error) => {
  process.stderr.write(`validator failed: ${error}\n`);
  process.exit(2);
});
