// Loads a terrain pyramid in CesiumJS (npm `cesium`, in .tools) inside headless Debian
// Chromium (driven by playwright-core), through CesiumTerrainProvider.fromUrl, and samples
// it with sampleTerrainMostDetailed; a TERRAIN_URL ending in tileset.json is 3D Tiles
// terrain, loaded through Cesium3DTilesTerrainProvider.fromUrl (its levels are read after
// sampling: its availability comes with the subtrees the sampling loads).
// Usage: node cesium_sample.cjs PAGE_URL TERRAIN_URL POINTS_JSON_FILE [Z/X/Y]
// Prints {heights, consoleErrors, failedRequests, levels, tiles, tiling} (each point's
// tile at its level, and the provider's tiling scheme); with Z/X/Y, the provider asks
// for water masks too and the result adds that tile's (TMS numbering) {hasWaterMask,
// waterMask} as CesiumJS decoded it (a 3D Tiles tile's image: its red channel, row by row). Exit code 3: Chromium cannot
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
      // 3D Tiles availability is known only once the subtrees are loaded.
      let levels = tiles3d ? null : levelsOf();
      await Cesium.sampleTerrainMostDetailed(provider, positions);
      if (tiles3d) levels = levelsOf();
      // The tile of each point at its level, as the provider's tiling scheme has it:
      // [x, y (from the north), west, south, east, north (degrees)].
      const scheme = provider.tilingScheme;
      const tiles = positions.map((c, k) => {
        const xy = scheme.positionToTileXY(c, levels[k]);
        const r = scheme.tileXYToRectangle(xy.x, xy.y, levels[k]);
        return [xy.x, xy.y, r.west, r.south, r.east, r.north].map(
          (v, i) => (i < 2 ? v : Cesium.Math.toDegrees(v)));
      });
      const tiling = scheme instanceof Cesium.WebMercatorTilingScheme ? 'mercator' : 'geographic';
      const out = { heights: positions.map((c) => c.height), levels, tiles, tiling };
      if (waterTile) {
        const [z, x, y] = waterTile.split('/').map(Number);
        // Z/X/Y as the pyramid names it (TMS, y = 0 in the south); CesiumJS counts rows
        // from the north.
        const data = await provider.requestTileGeometry(x, (1 << z) - 1 - y, z);
        out.hasWaterMask = provider.hasWaterMask;
        let mask = data.waterMask;
        if (mask instanceof ImageBitmap) {
          // 3D Tiles: the property texture's image; CesiumJS samples its red channel.
          const canvas = new OffscreenCanvas(mask.width, mask.height);
          const context2d = canvas.getContext('2d');
          context2d.drawImage(mask, 0, 0);
          const rgba = context2d.getImageData(0, 0, mask.width, mask.height).data;
          mask = rgba.filter((_, i) => i % 4 === 0);
        }
        out.waterMask = mask ? Array.from(mask) : null;
      }
      return out;
    }, { terrainUrl, points, waterTile });
    console.log(JSON.stringify({ ...result, consoleErrors, failedRequests }));
  } finally {
    await context.close();
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
})().catch((e) => { console.error(e && e.stack || String(e)); process.exit(1); });
