#!/usr/bin/env python3
"""Benchmark of point input: points/s and bytes per point for read, triangulate and
decimate, and triangles kept against the full Delaunay triangulation.

Inputs: the LAS/LAZ files in <shared>/data/points/, and --points (default 1 M and 20 M)
points sampled from a DEM of <shared>/data/dem/ (random positions, uniform over the valid
cells; heights bilinear from the four corner samples; millimetre positions and heights),
written as a CSV to a temporary directory and read back by tinsmith like any survey file.

Peers, on the sampled points: SciPy's Delaunay (Qhull) for the full TIN's time, standing in
for PDAL's filters.delaunay, which Debian 12 does not package; and on the DEM the points
came from, pydelatin (hmm's greedy insertion) and `tinsmith mesh DEM` at the same bound,
for the triangles a gridded input keeps (the target: the points' TIN at most 1.5 times
tinsmith's gridded one).

Each input runs `tinsmith mesh IN -o OUT.ply --max-error E --report R.json` under
/usr/bin/time: the report gives each phase's seconds and the point and triangle counts,
time gives the peak RSS. Bytes per point are (peak RSS - the RSS of the same command on
a 3-point file) / points read, so the binary's own resident size is left out. Prints a
Markdown table.

Usage (from the repository root, after `cargo build --release`; numpy, rasterio, scipy
and pydelatin in the Python that runs it, as `make bench-points` installs them in .venv):
    python bench/points.py --shared ../shared [--bound 0.1] [--dem codem_dem_1m.tif]
        [--points 1000000,20000000]
"""

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time

import numpy as np

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


def dem_grid(dem):
    """The DEM's heights (NaN = nodata) and its geotransform, through rasterio."""
    import rasterio

    with rasterio.open(dem) as src:
        z = src.read(1, masked=True).astype("f8").filled(np.nan)
        return z, src.transform


def dem_points(dem, n, work, seed=1):
    """n random points on the DEM (positions uniform over the cells whose four corner
    samples are valid, heights bilinear from them), as a CSV; returns its path and the
    points' x, y."""
    z, t = dem_grid(dem)
    valid = np.isfinite(z)
    cells = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]
    rows, cols = np.nonzero(cells)
    rng = np.random.default_rng(seed)
    out = os.path.join(work, f"dem_points_{n}.csv")
    xs, ys = [], []
    with open(out, "w") as f:
        f.write("x,y,z\n")
        for start in range(0, n, 1_000_000):
            m = min(1_000_000, n - start)
            k = rng.integers(0, len(rows), m)
            i, j = rows[k], cols[k]
            u, v = rng.random(m), rng.random(m)
            h = (z[i, j] * (1 - u) * (1 - v) + z[i, j + 1] * u * (1 - v)
                 + z[i + 1, j] * (1 - u) * v + z[i + 1, j + 1] * u * v)
            # Sample centres: column j at x = c + (j + 0.5) a, row i at y = f + (i + 0.5) e.
            x = t.c + (j + 0.5 + u) * t.a
            y = t.f + (i + 0.5 + v) * t.e
            np.savetxt(f, np.column_stack([x, y, h]), fmt="%.3f", delimiter=",")
            xs.append(np.round(x, 3))
            ys.append(np.round(y, 3))
    return out, np.concatenate(xs), np.concatenate(ys)


def scipy_delaunay(x, y):
    """Seconds and triangles of SciPy's Delaunay (Qhull) of the distinct points."""
    from scipy.spatial import Delaunay

    xy = np.unique(np.column_stack([x, y]), axis=0)
    xy -= xy.mean(axis=0)  # Qhull is faster and exact enough near the origin
    t = time.perf_counter()
    tri = Delaunay(xy)
    return time.perf_counter() - t, len(tri.simplices)


def pydelatin_triangles(dem, bound):
    """Triangles pydelatin keeps on the DEM at `bound` (nodata filled with the minimum, as
    pydelatin takes no nodata)."""
    from pydelatin import Delatin

    z, _ = dem_grid(dem)
    z = np.where(np.isfinite(z), z, np.nanmin(z))
    d = Delatin(z, max_error=bound)
    return len(d.triangles)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bound", type=float, default=0.1)
    ap.add_argument("--dem", default="codem_dem_1m.tif")
    ap.add_argument("--points", default="1000000,20000000", help="comma-separated counts")
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
        sampled = []
        for n in (int(p) for p in a.points.split(",")):
            path, x, y = dem_points(dem, n, work)
            inputs.append((f"{n:,} points on {a.dem}", [path]))
            sampled.append((n, x, y))
        print(f"Bound {a.bound}; bytes/point = (peak RSS - {base / 2**20:.0f} MiB) / points read\n")
        print("| input | points | read pts/s | triangulate pts/s | decimate pts/s | bytes/point | peak RSS | Delaunay triangles | kept | kept/Delaunay |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        kept = {}
        for name, args in inputs:
            r, rss = run([*args, "--max-error", str(a.bound)], work)
            n = r["points_read"]
            s = r["seconds"]
            rate = lambda t: f"{n / t / 1e6:.2f} M" if t > 0 else "-"
            kept[name] = r
            print(
                f"| {name} | {n:,} | {rate(s['read'])} | {rate(s['triangulate'])} | {rate(s['decimate'])} "
                f"| {(rss - base) / n:.0f} | {rss / 2**30:.2f} GiB | {r['delaunay_triangles']:,} | {r['triangles']:,} "
                f"| {r['triangles'] / r['delaunay_triangles']:.3f} |"
            )
        gridded, _ = run([dem, "--max-error", str(a.bound)], work)
        hmm = pydelatin_triangles(dem, a.bound)
        print(f"\nOn {a.dem} itself at {a.bound}: tinsmith keeps {gridded['triangles_after']:,} "
              f"triangles, pydelatin {hmm:,}.\n")
        print("| points | SciPy Delaunay (Qhull) s | its pts/s | tinsmith triangulate pts/s | tinsmith kept / tinsmith gridded | tinsmith kept / pydelatin gridded |")
        print("|---:|---:|---:|---:|---:|---:|")
        for n, x, y in sampled:
            seconds, _ = scipy_delaunay(x, y)
            r = kept[f"{n:,} points on {a.dem}"]
            print(f"| {n:,} | {seconds:.2f} | {n / seconds / 1e6:.2f} M "
                  f"| {r['points_read'] / r['seconds']['triangulate'] / 1e6:.2f} M "
                  f"| {r['triangles'] / gridded['triangles_after']:.2f} | {r['triangles'] / hmm:.2f} |")


if __name__ == "__main__":
    main()
