// Decodes quantized-mesh tiles with the independent HERE decoder (npm
// @here/quantized-mesh-decoder, installed into .tools by `make oracles`) and prints one
// JSON object per line: header, u/v/height, triangle indices, W/S/E/N edge lists, normals
// (oct bytes), the water mask's bytes and metadata. Arguments: tile files (gzipped or not).
'use strict';
const fs = require('fs');
const path = require('path');
const zlib = require('zlib');
const root = path.resolve(__dirname, '..', '..');
const decoder = require(path.join(root, '.tools', 'node_modules', '@here', 'quantized-mesh-decoder'));
const decode = decoder.default;

for (const file of process.argv.slice(2)) {
  let bytes = fs.readFileSync(file);
  const gzipped = bytes.length >= 2 && bytes[0] === 0x1f && bytes[1] === 0x8b;
  if (gzipped) bytes = zlib.gunzipSync(bytes);
  // A standalone ArrayBuffer: the decoder indexes dataView.buffer at absolute offsets.
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length);
  const t = decode(buffer);
  const n = t.vertexData.length / 3;
  const ext = t.extensions || {};
  console.log(JSON.stringify({
    file,
    gzipped,
    header: t.header,
    u: Array.from(t.vertexData.subarray(0, n)),
    v: Array.from(t.vertexData.subarray(n, 2 * n)),
    h: Array.from(t.vertexData.subarray(2 * n, 3 * n)),
    indexBytes: t.triangleIndices.BYTES_PER_ELEMENT,
    triangles: Array.from(t.triangleIndices),
    west: Array.from(t.westIndices),
    south: Array.from(t.southIndices),
    east: Array.from(t.eastIndices),
    north: Array.from(t.northIndices),
    normals: ext.vertexNormals ? Array.from(ext.vertexNormals) : null,
    waterMask: ext.waterMask ? Array.from(new Uint8Array(ext.waterMask)) : null,
    metadata: ext.metadata === undefined ? null : ext.metadata,
  }));
}
