#!/usr/bin/env python3
"""Pictures for docs/results.md ("Pictures"): tinsmith's TIN beside hmm's (pydelatin) at
the same epsilon on two real DEMs, each drawn by `tinsmith preview` over the DEM's
hillshade, with both meshes' triangle counts and their error measured by `tinsmith verify`;
then two CesiumJS screenshots of `tinsmith tiles` pyramids served by `tinsmith serve` (a
global view of ETOPO5, a close view of Big Tujunga), by bench/cesium_shot.cjs in headless
Chromium (CesiumJS and playwright-core from `make deps`).

Setup and run (from the repository root; `make pictures` does both):
    .venv/bin/pip install pydelatin numpy rasterio
    .venv/bin/python bench/pictures.py [--shared ../shared] [--out docs/images]
Prints the Markdown of the section.
"""
import argparse
import importlib.util
import pathlib
import os
import subprocess
import sys
import tempfile

import numpy as np
from pydelatin import Delatin

ROOT = pathlib.Path(__file__).resolve().parent.parent
# (case of bench/compare.py, epsilon, picture size)
PICTURES = [("bigtujunga", 30.0, 800), ("fuji", 20.0, 560)]
# (name, DEM under ../shared/data, terrain directory, camera: lon, lat, height m, heading,
# pitch, vertical exaggeration; variant: none, "below-0" for a water mask of the DEM's
# samples below 0 m, "data-only" for `--data-only`, "mercator" for `--tiling mercator`, or
# "3dtiles" for `--format 3dtiles`, loaded through Cesium3DTilesTerrainProvider, or "base"
# for `--base` ETOPO5)
CESIUM = [
    ("cesium-global", "dem/etopo5_global_5arcmin.tif", "etopo5",
     (85, 25, 11_000_000, 0, -90, 20), None),
    ("cesium-close", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga",
     (-118.19, 34.16, 9_000, 20, -30, 1), None),
    ("cesium-water", "dem/etopo5_global_5arcmin.tif", "etopo5-water",
     (15, 38, 4_000_000, 0, -90, 20), "below-0"),
    ("cesium-water-close", "dem/etopo5_global_5arcmin.tif", "etopo5-water",
     (24.5, 35.0, 700_000, 0, -45, 20), "below-0"),
    ("cesium-global-3dtiles", "dem/etopo5_global_5arcmin.tif", "etopo5-3dtiles",
     (85, 25, 11_000_000, 0, -90, 20), "3dtiles"),
    ("cesium-regional-globe", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga",
     (-118.19, 34.16, 15_000_000, 0, -90, 1), None),
    ("cesium-regional-data-only", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-data-only",
     (-118.19, 34.16, 15_000_000, 0, -90, 1), "data-only"),
    ("cesium-close-3dtiles", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-3dtiles",
     (-118.19, 34.16, 9_000, 20, -30, 1), "3dtiles"),
    ("cesium-60km", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga",
     (-118.19, 34.16, 60_000, 20, -60, 1), None),
    ("cesium-60km-3dtiles", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-3dtiles",
     (-118.19, 34.16, 60_000, 20, -60, 1), "3dtiles"),
    ("cesium-mercator-global", "dem/etopo5_global_5arcmin.tif", "etopo5-mercator",
     (85, 25, 11_000_000, 0, -90, 20), "mercator"),
    ("cesium-mercator-close", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-mercator",
     (-118.19, 34.16, 9_000, 20, -30, 1), "mercator"),
    ("cesium-base-globe", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-base",
     (-118.19, 34.16, 15_000_000, 0, -90, 20), "base"),
    ("cesium-base-60km", "dem/topotoolbox_bigtujunga_30m.tif", "bigtujunga-base",
     (-118.19, 34.16, 60_000, 20, -60, 1), "base"),
]
PAGE = ("<!doctype html><html><head><link rel=\"icon\" href=\"data:,\">"
        "<script>window.CESIUM_BASE_URL = '/cesium/';</script>"
        "<script src=\"/cesium/Cesium.js\"></script>"
        "<link href=\"/cesium/Widgets/widgets.css\" rel=\"stylesheet\">"
        "<style>html,body,#v{width:100%;height:100%;margin:0;padding:0;overflow:hidden}</style>"
        "</head><body><div id=\"v\"></div></body></html>\n")


def compare_module():
    """bench/compare.py, for its DEM list, loader and writers."""
    spec = importlib.util.spec_from_file_location("compare", ROOT / "bench/compare.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(cmd):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{cmd[0]} {cmd[1]} failed: {p.stderr}")
    return p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bin", default=str(ROOT / "target/release/tinsmith"))
    ap.add_argument("--out", default=str(ROOT / "docs/images"))
    ap.add_argument("--only", default="",
                    help="comma-separated CesiumJS pictures to redraw alone (e.g. "
                         "cesium-water-close); the TIN pictures are then skipped")
    args = ap.parse_args()
    compare = compare_module()
    data = pathlib.Path(args.shared) / "data"
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for name, eps, size in ([] if args.only else PICTURES):
            rel, decode = compare.CASES[name]
            grid = compare.load(data / rel, decode)
            raster = tmp / f"{name}.tif"
            compare.write_tif(raster, grid)
            h, w = grid.shape
            ours, theirs = tmp / f"{name}-tinsmith.ply", tmp / f"{name}-hmm.obj"
            run([args.bin, "mesh", raster, "-o", ours, "--max-error", eps, "--pixel-coords",
                 "-q", "--threads", "1"])
            tin = Delatin(grid.astype(np.float32), max_error=eps)
            compare.write_obj(theirs, tin.vertices, tin.triangles, h)
            counts = {}
            for label, mesh in (("tinsmith", ours), ("hmm", theirs)):
                report = compare.verify(args.bin, raster, mesh, eps)
                counts[label] = (report["triangles"], report["max_error"])
                png = out / f"{name}-{label}.png"
                run([args.bin, "preview", raster, mesh, "-o", png, "--pixel-coords",
                     "--size", size])
            (t_tris, t_err), (h_tris, h_err) = counts["tinsmith"], counts["hmm"]
            lines += [
                f"**{name}** ({w} x {h} samples), ε = {eps:g}: tinsmith {t_tris:,} triangles "
                f"(measured max error {t_err:.3g}), hmm {h_tris:,} (measured {h_err:.3g}): "
                f"{t_tris / h_tris:.2f} x.",
                "",
                f"| tinsmith, {t_tris:,} triangles | hmm, {h_tris:,} triangles |",
                "|---|---|",
                f"| ![tinsmith's TIN of {name}](images/{name}-tinsmith.png) "
                f"| ![hmm's TIN of {name}](images/{name}-hmm.png) |",
                "",
            ]
        lines += cesium_pictures(args, data, out, tmp)
    print("\n".join(lines))


def cesium_pictures(args, data, out, tmp):
    """Builds each CESIUM pyramid, serves them, screenshots each; the Markdown lines."""
    site = tmp / "site"
    site.mkdir()
    (site / "index.html").write_text(PAGE)
    os.symlink(ROOT / ".tools/node_modules/cesium/Build/Cesium", site / "cesium")
    only = set(filter(None, args.only.split(",")))
    unknown = only - {c[0] for c in CESIUM}
    if unknown:
        sys.exit(f"--only: no CesiumJS picture named {', '.join(sorted(unknown))}")
    shots = [c for c in CESIUM if not only or c[0] in only]
    built = set()
    for _, dem, terrain, _, variant in shots:
        if terrain in built:
            continue
        built.add(terrain)
        extra = {"data-only": ["--data-only"], "mercator": ["--tiling", "mercator"],
                 "3dtiles": ["--format", "3dtiles"],
                 "base": ["--base", data / "dem/etopo5_global_5arcmin.tif"]}.get(variant, [])
        if variant == "below-0":
            # 255 (water) where the DEM is below 0 m, 0 elsewhere: -scale maps 0 m to 0
            # and -1 m to 255, and Byte clips the rest.
            mask = tmp / f"{terrain}-mask.tif"
            run(["gdal_translate", "-q", "-ot", "Byte", "-scale", "0", "-1", "0", "255",
                 data / dem, mask])
            extra = ["--water", mask, "--max-zoom", "4"]
        run([args.bin, "tiles", data / dem, "-o", site / terrain, "--normals",
             "--vertical-datum", "ellipsoid", "-q", *extra])
    server = subprocess.Popen([args.bin, "serve", site, "--port", "0"], stdout=subprocess.PIPE,
                              text=True)
    try:
        base = server.stdout.readline().strip().rsplit(" ", 1)[-1]
        for name, _, terrain, view, variant in shots:
            url = f"{base}{terrain}/" + ("tileset.json" if variant == "3dtiles" else "")
            run(["node", ROOT / "bench/cesium_shot.cjs", f"{base}index.html",
                 url, out / f"{name}.png", *view,
                 *(["water"] if variant == "below-0" else [])])
    finally:
        server.kill()
        server.wait()
    return [
        "CesiumJS 1.140 in headless Chromium, pyramids by `tinsmith tiles --normals` served by "
        "`tinsmith serve`, no imagery, lit by the pyramids' normals: ETOPO5 (levels 0–4, "
        "heights exaggerated 20 x) and Big Tujunga (30 m, levels 0–12, not exaggerated).",
        "",
        "| ETOPO5, the whole globe | Big Tujunga, close |",
        "|---|---|",
        "| ![ETOPO5 in CesiumJS](images/cesium-global.png) "
        "| ![Big Tujunga in CesiumJS](images/cesium-close.png) |",
        "",
        "Water masks: ETOPO5 (levels 0–4) with `--water MASK`, the mask 1 where ETOPO5 is "
        "below 0 m, loaded with `requestWaterMask`: CesiumJS draws its specular water over "
        "the Mediterranean, the Black Sea and the Red Sea (each tile's mask is 256 x 256 "
        "cells, about 5 km at level 4, which shows as the coasts' steps).",
        "",
        "Closer, 700 km over Crete looking north to the Aegean: the sea lit as water, "
        "the islands as land, each at the 5 km of its tile's mask.",
        "",
        "| ETOPO5 with water, the Mediterranean | closer, the Aegean |",
        "|---|---|",
        "| ![ETOPO5 with water masks in CesiumJS](images/cesium-water.png) "
        "| ![the Aegean's water masks in CesiumJS](images/cesium-water-close.png) |",
        "",
        "A regional pyramid (Big Tujunga, 30 m, about 36 x 19 km) seen from 15,000 km: as "
        "built (the globe beyond the raster flat at 0 m, both root tiles written) CesiumJS "
        "draws the whole globe; with `--data-only`, a speck and no globe.",
        "",
        "| Big Tujunga, whole globe | Big Tujunga, `--data-only` |",
        "|---|---|",
        "| ![the whole globe](images/cesium-regional-globe.png) "
        "| ![a speck, no globe](images/cesium-regional-data-only.png) |",
        "",
        "The same Big Tujunga pyramid as 3D Tiles (`--format 3dtiles`, loaded through "
        "`Cesium3DTilesTerrainProvider`) and as quantized-mesh, at the same camera 60 km up: "
        "the two pictures differ by 0.01 of 255 on average per pixel (at most 16). Close, "
        "9 km up, at the camera of the quantized-mesh picture above: the same relief, with "
        "the globe beyond the raster flat at 0 m (the cliffs at the raster's edge); the two "
        "close pictures differ by 0.02 of 255 on average per pixel (at most 33). "
        "bench/cesium_shot.cjs shoots once `globe.tilesLoaded` has held for 30 frames "
        "running: it also holds for a frame between levels, and shooting on the first such "
        "frame gave, in 6 of 18 runs at the close camera, a coarse level's picture (blank "
        "grey, or blurred relief; docs/notes/2026-12-05-close-picture.md).",
        "",
        "| quantized-mesh, 60 km | 3D Tiles, 60 km | 3D Tiles, close |",
        "|---|---|---|",
        "| ![quantized-mesh](images/cesium-60km.png) "
        "| ![3D Tiles](images/cesium-60km-3dtiles.png) "
        "| ![3D Tiles, close](images/cesium-close-3dtiles.png) |",
        "",
        "ETOPO5 as 3D Tiles at the camera of the global quantized-mesh picture above: the "
        "two pictures differ by at most 1 of 255 in a pixel (5e-6 on average).",
        "",
        "![ETOPO5 as 3D Tiles in CesiumJS](images/cesium-global-3dtiles.png)",
        "",
        "The first two pyramids with `--tiling mercator` (Web Mercator tiles, EPSG:3857; "
        "ETOPO5 to level 5, its own), at the same cameras:",
        "",
        "| ETOPO5, Web Mercator | Big Tujunga, Web Mercator |",
        "|---|---|",
        "| ![ETOPO5 in Web Mercator tiles](images/cesium-mercator-global.png) "
        "| ![Big Tujunga in Web Mercator tiles](images/cesium-mercator-close.png) |",
        "",
        "Big Tujunga over ETOPO5 (`--base`): from 15,000 km (heights exaggerated 20 x) the "
        "globe is ETOPO5's; 60 km up, at the camera of the quantized-mesh picture above, the "
        "ground around the raster is ETOPO5's slopes instead of the flat globe at 0 m, with a "
        "step at the raster's edge where ETOPO5's 9 km samples meet its 30 m ones.",
        "",
        "| Big Tujunga `--base` ETOPO5, the globe | the same, 60 km |",
        "|---|---|",
        "| ![the globe from the base](images/cesium-base-globe.png) "
        "| ![the base around the raster](images/cesium-base-60km.png) |",
        "",
    ]


if __name__ == "__main__":
    main()
