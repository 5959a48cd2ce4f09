#!/usr/bin/env python3
"""Benchmark of point input: points/s and bytes per point for read, triangulate and
decimate, and triangles kept against the full Delaunay triangulation.

Inputs: the LAS/LAZ files in <shared>/data/points/, and 1 M points sampled from a DEM of
<shared>/data/dem/ (random positions, uniform over the valid cells; heights bilinear
from the four corner samples; millimetre positions and heights), written as a CSV to a
temporary directory and read back by tinsmith like any survey file.

Each input runs `tinsmith mesh IN -o OUT.ply --max-error E --report R.json` under
/usr/bin/time: the report gives each phase's seconds and the point and triangle counts,
time gives the peak RSS. Bytes per point are (peak RSS - the RSS of the same command on
a 3-point file) / points read, so the binary's own resident size is left out. Prints a
Markdown table.

Usage (from the repository root, after `cargo build --release`):
    python3 bench/points.py --shared ../shared [--bound 0.1] [--dem codem_dem_1m.tif]
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile

BIN = os.path.join(os.path.dirname(__file__), "..", "target", "release", "tinsmith")


def binary():
    target = os.environ.get("CARGO_TARGET_DIR")
    if target:
        return os.path.join(target, "release", "tinsmith")
    return BIN


def run(args, work):
    """Runs tinsmith under /usr/bin/time; returns (report dict, peak RSS bytes)."""
    report = os.path.join(work, "r.json")
    out = os.path.join(work, "out.ply")
    cmd = ["/usr/bin/time", "-f", "%M", binary(), "mesh", *args, "-o", out, "--report", report, "-q"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    rss = int(p.stderr.strip().splitlines()[-1]) * 1024
    with open(report) as f:
        return json.load(f), rss


def dem_points(dem, n, work, seed=1):
    """n random points on the DEM, bilinear heights, as a CSV; returns its path."""
    xyz = os.path.join(work, "dem.xyz")
    subprocess.run(["gdal_translate", "-q", "-of", "XYZ", dem, xyz], check=True)
    rows = {}
    xs = set()
    with open(xyz) as f:
        for line in f:
            x, y, z = (float(v) for v in line.split())
            rows.setdefault(y, {})[x] = z
            xs.add(x)
    ys = sorted(rows, reverse=True)
    xs = sorted(xs)
    nodata = subprocess.run(["gdalinfo", dem], capture_output=True, text=True).stdout
    nd = None
    for line in nodata.splitlines():
        if "NoData Value=" in line:
            nd = float(line.split("=")[1])
    grid = [[rows[y].get(x) for x in xs] for y in ys]
    cells = [
        (i, j)
        for i in range(len(ys) - 1)
        for j in range(len(xs) - 1)
        if all(grid[a][b] is not None and grid[a][b] != nd for a, b in ((i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)))
    ]
    rng = random.Random(seed)
    out = os.path.join(work, "dem_points.csv")
    with open(out, "w") as f:
        f.write("x,y,z\n")
        for _ in range(n):
            i, j = rng.choice(cells)
            u, v = rng.random(), rng.random()
            z = (grid[i][j] * (1 - u) * (1 - v) + grid[i][j + 1] * u * (1 - v)
                 + grid[i + 1][j] * (1 - u) * v + grid[i + 1][j + 1] * u * v)
            x = xs[j] + u * (xs[j + 1] - xs[j])
            y = ys[i] + v * (ys[i + 1] - ys[i])
            f.write(f"{x:.3f},{y:.3f},{z:.3f}\n")
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bound", type=float, default=0.1)
    ap.add_argument("--dem", default="codem_dem_1m.tif")
    ap.add_argument("--points", type=int, default=1_000_000)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as work:
        tiny = os.path.join(work, "tiny.csv")
        with open(tiny, "w") as f:
            f.write("0 0 0\n1 0 0\n0 1 1\n")
        _, base = run([tiny, "--max-error", "1"], work)
        inputs = []
        d = os.path.join(a.shared, "data", "points")
        for name in sorted(os.listdir(d)):
            extra = ["--crs", "EPSG:32104"] if name.startswith("wkt_geotiff") else []
            inputs.append((name, [os.path.join(d, name), *extra]))
        dem = os.path.join(a.shared, "data", "dem", a.dem)
        inputs.append((f"{a.points:,} points on {a.dem}", [dem_points(dem, a.points, work)]))
        print(f"Bound {a.bound}; bytes/point = (peak RSS - {base / 2**20:.0f} MiB) / points read\n")
        print("| input | points | read pts/s | triangulate pts/s | decimate pts/s | bytes/point | Delaunay triangles | kept | kept/Delaunay |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for name, args in inputs:
            r, rss = run([*args, "--max-error", str(a.bound)], work)
            n = r["points_read"]
            s = r["seconds"]
            rate = lambda t: f"{n / t / 1e6:.2f} M" if t > 0 else "-"
            print(
                f"| {name} | {n:,} | {rate(s['read'])} | {rate(s['triangulate'])} | {rate(s['decimate'])} "
                f"| {(rss - base) / n:.0f} | {r['delaunay_triangles']:,} | {r['triangles']:,} "
                f"| {r['triangles'] / r['delaunay_triangles']:.3f} |"
            )


if __name__ == "__main__":
    main()
