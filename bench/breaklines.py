#!/usr/bin/env python3
"""Benchmark of breaklines with point input: time and triangles of `tinsmith mesh` on a
LAS/LAZ file with and without a synthetic breakline set.

The breaklines: 5 rows (at 1/6 .. 5/6 of the file's y extent) and 3 columns (1/4, 1/2,
3/4 of its x extent), each over the middle 60 % of the other axis with 21 vertices, 2D,
written to a GeoPackage in the file's CRS by ogr2ogr (laspy reads the header). Each
configuration runs `--repeat` times under /usr/bin/time; the table gives the best wall
time, the report's phases of that run, triangles and vertices kept, and whether
`tinsmith verify --breaklines` passes (it must for the breakline runs and must not for
the plain ones). Prints a Markdown table.

Usage (from the repository root, after `cargo build --release`):
    .venv/bin/python bench/breaklines.py ../shared/data/points/autzen_trim_110k.laz \
        [--bound 0.1] [--classes 1,2] [--repeat 3]
"""

import argparse
import json
import os
import subprocess
import tempfile

import laspy


def binary():
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(
        os.path.dirname(__file__), "..", "target"
    )
    return os.path.join(target, "release", "tinsmith")


def breaklines(las, work):
    header = laspy.read(las).header
    (x0, y0, _), (x1, y1, _) = header.mins, header.maxs
    lines = []
    for k in range(1, 6):
        y = round(y0 + (y1 - y0) * k / 6, 2)
        lines.append([[round(x0 + (x1 - x0) * (0.2 + 0.6 * i / 20), 2), y] for i in range(21)])
    for k in range(1, 4):
        x = round(x0 + (x1 - x0) * k / 4, 2)
        lines.append([[x, round(y0 + (y1 - y0) * (0.2 + 0.6 * i / 20), 2)] for i in range(21)])
    features = [
        {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": c}}
        for c in lines
    ]
    geojson = os.path.join(work, "rows.json")
    with open(geojson, "w") as f:
        json.dump({"type": "FeatureCollection", "features": features}, f)
    wkt = os.path.join(work, "crs.wkt")
    with open(wkt, "w") as f:
        f.write(header.parse_crs().to_wkt())
    gpkg = os.path.join(work, "rows.gpkg")
    subprocess.run(["ogr2ogr", "-f", "GPKG", "-a_srs", wkt, gpkg, geojson], check=True)
    return gpkg


def main():
    p = argparse.ArgumentParser()
    p.add_argument("las")
    p.add_argument("--bound", default="0.1")
    p.add_argument("--classes", default="1,2")
    p.add_argument("--repeat", type=int, default=3)
    a = p.parse_args()
    work = tempfile.mkdtemp()
    gpkg = breaklines(a.las, work)
    print("| breaklines | wall s (best) | triangulate s | decimate s | triangles | vertices | constrained edges | verify --breaklines |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for extra in ([], ["--breaklines", gpkg]):
        best = None
        out = os.path.join(work, "tin.ply")
        for _ in range(a.repeat):
            report = os.path.join(work, "r.json")
            cmd = ["/usr/bin/time", "-f", "%e", binary(), "mesh", a.las, "-o", out,
                   "--max-error", a.bound, "--classes", a.classes, "--report", report] + extra
            run = subprocess.run(cmd, capture_output=True, text=True, check=True)
            wall = float(run.stderr.strip().splitlines()[-1])
            if best is None or wall < best[0]:
                with open(report) as f:
                    best = (wall, json.load(f))
        verify = subprocess.run(
            [binary(), "verify", a.las, out, "--max-error", a.bound, "--classes", a.classes,
             "--breaklines", gpkg],
            capture_output=True, text=True,
        )
        wall, r = best
        edges = r.get("breaklines", {}).get("constrained_edges", 0)
        print(f"| {'8 lines' if extra else 'none'} | {wall:.2f} | {r['seconds']['triangulate']:.2f} | "
              f"{r['seconds']['decimate']:.2f} | {r['triangles']:,} | {r['vertices']:,} | {edges} | "
              f"{'passed' if verify.returncode == 0 else 'failed'} |")


if __name__ == "__main__":
    main()
