#!/usr/bin/env python3
"""Peak memory of `tinsmith preview` on rasters from 2048^2 to 16384^2 samples.

Builds Float32 DEMs from ETOPO5 (resampled with gdalwarp, cubic, as bench/tiles.py does)
in a work directory outside the repository, meshes each tile by tile at a loose bound
(so that the mesh stays small beside the raster), then draws the default 1600-pixel
preview under /usr/bin/time and prints a Markdown table: the raster's samples as f64,
the mesh file, which path the preview took (the raster read whole and the mesh verified
at every sample, or only the drawn samples read), peak RSS and wall time. Rasters up to
tinsmith's whole-read limit are drawn both ways (the drawn-samples path forced by the
test hook), so the two paths are compared on the same input in the same run.

Usage (from the repository root):
    cargo build --release
    python3 bench/preview_memory.py [--shared ../shared] [--work /tmp/tinsmith-preview]
        [--sizes 2048,4096,8192,16384] [--max-error 50] [--out FILE.md]
"""
import argparse
import os
import pathlib
import subprocess
import sys

WHOLE_READ_SAMPLES = 1 << 25  # tinsmith_pipeline::preview::WHOLE_READ_SAMPLES


def sh(cmd, env=None):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return p


def build_dem(shared, work, size):
    path = work / f"etopo5_{size}.tif"
    if not path.exists():
        src = shared / "data/dem/etopo5_global_5arcmin.tif"
        sh(["gdalwarp", "-q", "-overwrite", "-ts", str(size), str(size), "-r", "cubic",
            "-ot", "Float32", "-co", "TILED=YES", "-co", "COMPRESS=DEFLATE",
            "-co", "BIGTIFF=IF_SAFER", str(src), str(path)])
    return path


def timed(cmd, work, env=None):
    """Runs cmd under GNU time; returns (wall s, peak RSS MB, stderr)."""
    timing = work / "time.txt"
    p = sh(["/usr/bin/time", "-f", "%e %M", "-o", str(timing)] + cmd, env=env)
    wall, rss = open(timing).read().split()[-2:]
    return float(wall), int(rss) / 1024, p.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--work", default="/tmp/tinsmith-preview")
    ap.add_argument("--sizes", default="2048,4096,8192,16384")
    ap.add_argument("--max-error", default="50")
    ap.add_argument("--binary", default="target/release/tinsmith")
    ap.add_argument("--out")
    args = ap.parse_args()
    shared, work = pathlib.Path(args.shared), pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    binary = str(pathlib.Path(args.binary).resolve())
    lines = [
        f"Default preview (1600 pixels, hillshade and wireframe) of ETOPO5 resampled to "
        f"n x n Float32, meshed tile by tile within {args.max_error} m. "
        f"Command: `python3 bench/preview_memory.py --sizes {args.sizes} "
        f"--max-error {args.max_error}`.",
        "",
        "| raster | samples as f64 | mesh file | path | peak RSS | RSS / samples as f64 "
        "| wall |",
        "|---|---:|---:|---|---:|---:|---:|",
    ]
    for size in [int(s) for s in args.sizes.split(",")]:
        dem = build_dem(shared, work, size)
        mesh = work / f"etopo5_{size}.ply"
        if not mesh.exists():
            sh([binary, "mesh", str(dem), "--max-error", args.max_error, "-o", str(mesh),
                "-q"])
        f64_mb = size * size * 8 / 2**20
        mesh_mb = mesh.stat().st_size / 2**20
        paths = [("drawn samples", {"TINSMITH_TEST_WHOLE_READ_SAMPLES": "0"})]
        if size * size <= WHOLE_READ_SAMPLES:
            paths.insert(0, ("whole, verified", {}))
        for name, extra in paths:
            env = dict(os.environ, **extra)
            png = work / f"etopo5_{size}.png"
            wall, rss, err = timed([binary, "preview", str(dem), str(mesh), "-o", str(png)],
                                   work, env)
            took = "drawn samples" if "not verified" in err else "whole, verified"
            if took != name:
                sys.exit(f"{size}: expected the {name} path, took {took}: {err}")
            lines.append(
                f"| {size}^2 | {f64_mb:,.0f} MB | {mesh_mb:,.1f} MB | {name} | {rss:,.0f} MB "
                f"| {rss / f64_mb:.2f} | {wall:.1f} s |")
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        pathlib.Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
