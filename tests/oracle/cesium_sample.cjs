// Loads a terrain pyramid in CesiumJS (npm `cesium`, in .tools) inside headless Debian
// Chromium (driven by playwright-core), through CesiumTerrainProvider.fromUrl, and samples
// it with sampleTerrainMostDetailed; a TERRAIN_URL ending in tileset.json is 3D Tiles
// terrain, loaded through Cesium3DTilesTerrainProvider.fromUrl (its levels are read after
// sampling: its availability comes with the subtrees the sampling loads).
// Usage: node cesium_sample.cjs PAGE_URL TERRAIN_URL POINTS_JSON_FILE [Z/X/Y]
// Prints {heights, consoleErrors, failedRequests, levels}; with Z/X/Y, the provider asks
// for water masks too and the result adds that tile's (TMS numbering) {hasWaterMask,
// waterMask} as CesiumJS decoded it. Exit code 3: Chromium cannot
// start (the caller may skip); any other non-zero code is a failure.
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const root = path.resolve(__dirname, '..', '..');
const { chromium } = require(path.join(root, '.tools', 'node_modules', 'playwright-core'));

(async () => {
  const [pageUrl, terrainUrl, pointsFile, waterTile] = process.argv.slice(2);
  const points = JSON.parse(fs.readFileSync(pointsFile, 'utf8'));
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tinsmith-chromium-'));
  let context;
  try {
    context = await chromium.launchPersistentContext(userDataDir, {
      executablePath: '/usr/bin/chromium',
      headless: true,
      args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
        '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
  } catch (e) {
    console.error('chromium cannot start: ' + e.message);
    process.exit(3);
  }
  const consoleErrors = [];
  const failedRequests = [];
  try {
    const page = await context.newPage();
    page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page.on('pageerror', (e) => consoleErrors.push(String(e)));
    page.on('requestfailed', (r) => failedRequests.push(r.url() + ' ' + (r.failure() || {}).errorText));
    page.on('response', (r) => { if (r.status() >= 400) failedRequests.push(r.url() + ' ' + r.status()); });
    await page.goto(pageUrl, { waitUntil: 'load', timeout: 60000 });
    const result = await page.evaluate(async ({ terrainUrl, points, waterTile }) => {
      const tiles3d = terrainUrl.endsWith('tileset.json');
      const options = { requestVertexNormals: true, requestWaterMask: Boolean(waterTile) };
      const provider = tiles3d
        ? await Cesium.Cesium3DTilesTerrainProvider.fromUrl(terrainUrl, options)
        : await Cesium.CesiumTerrainProvider.fromUrl(terrainUrl, options);
      const positions = points.map((p) => Cesium.Cartographic.fromDegrees(p[0], p[1], NaN));
      const levelsOf = () => positions.map((c) => provider.availability.computeMaximumLevelAtPosition(c));
      let levels = tiles3d ? null : levelsOf();
      await Cesium.sampleTerrainMostDetailed(provider, positions);
      if (tiles3d) levels = levelsOf();
      const out = { heights: positions.map((c) => c.height), levels };
      if (waterTile) {
        const [z, x, y] = waterTile.split('/').map(Number);
        // Z/X/Y as the pyramid names it (TMS, y = 0 in the south); CesiumJS counts rows
        // from the north.
        const data = await provider.requestTileGeometry(x, (1 << z) - 1 - y, z);
        out.hasWaterMask = provider.hasWaterMask;
        out.waterMask = data.waterMask ? Array.from(data.waterMask) : null;
      }
      return out;
    }, { terrainUrl, points, waterTile });
    console.log(JSON.stringify({ ...result, consoleErrors, failedRequests }));
  } finally {
    await context.close();
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
})().catch((e) => { console.error(e && e.stack || String(e)); process.exit(1); });
