// Runs the Khronos glTF validator (npm `gltf-validator`, installed by `make deps` into
// .tools/node_modules) on one file and prints its JSON report on stdout.
// Usage: node tests/oracles/gltf_validate.js FILE.glb
'use strict';
const fs = require('fs');
const path = require('path');

const modules = process.env.TINSMITH_NODE_MODULES
  || path.join(__dirname, '..', '..', '.tools', 'node_modules');
const validator = require(path.join(modules, 'gltf-validator'));

const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 100 })
  .then((report) => {
    process.stdout.write(JSON.stringify(report));
  })
  .catch((error) => {
    process.stderr.write(`validator failed: ${error}\n`);
    process.exit(2);
  });
