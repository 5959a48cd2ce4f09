// One screenshot of a terrain pyramid in CesiumJS (npm `cesium`, in .tools), in headless
// Debian Chromium (playwright-core; WebGL through SwiftShader): no imagery, the globe's
// base colour lit from over the viewer's left shoulder, so the relief shows by the
// pyramid's own normals. Used by bench/pictures.py (make pictures).
// Usage: node bench/cesium_shot.cjs PAGE_URL TERRAIN_URL OUT.png LON LAT HEIGHT_M
//        HEADING_DEG PITCH_DEG EXAGGERATION [water]
// With `water`, the provider asks for the pyramid's water masks and the globe draws
// water (CesiumJS's animated specular water) where they say. A TERRAIN_URL ending in
// tileset.json is 3D Tiles terrain, loaded through Cesium3DTilesTerrainProvider.
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const root = path.resolve(__dirname, "..");
const { chromium } = require(path.join(root, '.tools', 'node_modules', 'playwright-core'));
(async () => {
  const [pageUrl, terrainUrl, out, lon, lat, height, heading, pitch, exaggeration, water] = process.argv.slice(2);
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tinsmith-chromium-'));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium', headless: true,
    viewport: { width: 960, height: 600 },
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
      '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  try {
    const page = await context.newPage();
    page.on('console', (m) => console.error('console: ' + m.text()));
    page.on('pageerror', (e) => console.error('pageerror: ' + e));
    await page.goto(pageUrl, { waitUntil: 'load', timeout: 60000 });
    await page.evaluate(async ({ terrainUrl, view, water }) => {
      const provider = terrainUrl.endsWith('tileset.json')
        ? Cesium.Cesium3DTilesTerrainProvider : Cesium.CesiumTerrainProvider;
      const terrainProvider = await provider.fromUrl(terrainUrl, {
        requestVertexNormals: true, requestWaterMask: water,
      });
      const viewer = new Cesium.Viewer('v', {
        terrainProvider, baseLayer: false, baseLayerPicker: false, geocoder: false, homeButton: false,
        sceneModePicker: false, navigationHelpButton: false, animation: false, timeline: false,
        fullscreenButton: false, infoBox: false, selectionIndicator: false, skyBox: false, skyAtmosphere: false,
        contextOptions: { webgl: { preserveDrawingBuffer: true } },
      });
      viewer.scene.globe.baseColor = Cesium.Color.fromCssColorString('#d9d4c7');
      viewer.scene.globe.enableLighting = true;
      viewer.scene.globe.showGroundAtmosphere = false;
      // Finer tiles than CesiumJS's default for the view: a picture, not a frame rate.
      viewer.scene.globe.maximumScreenSpaceError = 1;
      viewer.scene.verticalExaggeration = view[5];
      viewer.scene.backgroundColor = Cesium.Color.WHITE;
      viewer.camera.setView({
        destination: Cesium.Cartesian3.fromDegrees(view[0], view[1], view[2]),
        orientation: { heading: Cesium.Math.toRadians(view[3]), pitch: Cesium.Math.toRadians(view[4]), roll: 0 },
      });
      // Light from over the viewer's left shoulder, whatever the view.
      const camera = viewer.scene.camera;
      const light = new Cesium.Cartesian3();
      Cesium.Cartesian3.add(camera.directionWC, Cesium.Cartesian3.multiplyByScalar(camera.rightWC, 0.6, new Cesium.Cartesian3()), light);
      Cesium.Cartesian3.add(light, Cesium.Cartesian3.multiplyByScalar(camera.upWC, -0.6, new Cesium.Cartesian3()), light);
      viewer.scene.light = new Cesium.DirectionalLight({ direction: Cesium.Cartesian3.normalize(light, light) });
      // Loaded: `globe.tilesLoaded` on 30 frames running. One frame is not enough: it is
      // also true for a frame or two between levels (the parents loaded, the children not
      // yet asked for), and a picture shot then shows the coarse levels, which from 9 km up
      // at pitch -30 deg fill the view with flat grey.
      const frames = 30;
      const timeoutMs = 240000;
      await new Promise((resolve, reject) => {
        let run = 0;
        const start = performance.now();
        const remove = viewer.scene.postRender.addEventListener(() => {
          run = viewer.scene.globe.tilesLoaded ? run + 1 : 0;
          if (run >= frames) {
            remove();
            resolve();
          } else if (performance.now() - start > timeoutMs) {
            remove();
            reject(new Error(`the view's tiles were not all loaded after ${timeoutMs / 1000} s`));
          }
        });
      });
      window.__viewer = viewer;
    }, { terrainUrl, view: [lon, lat, height, heading, pitch, exaggeration].map(Number), water: water === 'water' });
    await page.screenshot({ path: out });
  } finally {
    await context.close();
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
})().catch((e) => { console.error(e && e.stack || String(e)); process.exit(1); });
