#!/usr/bin/env python3
"""tinsmith vs hmm (pydelatin, the Python wrapper of hmm's C++ greedy insertion).

For each real DEM and each epsilon: run `tinsmith mesh` and pydelatin in the same run, both
single-threaded, verify BOTH outputs with `tinsmith verify`, and print triangles, seconds
and measured max error side by side, with the ratios the project targets:
triangles <= 0.85 x hmm, time <= 1.0 x hmm (<= 0.2 x where hmm keeps > 30 % of the full
grid's triangles), measured max error <= epsilon.

Setup (done by `make bench-compare`): a venv with pydelatin, numpy and rasterio:
    python3 -m venv .venv && .venv/bin/pip install pydelatin numpy rasterio
Usage:
    .venv/bin/python bench/compare.py [--shared ../shared] [--eps 0.5,1,5,30] [--out FILE.md]
        [--tinsmith-args "--error-model exact"] [--cases bigtujunga,fuji]
        [--baseline OLD_BINARY] [--repeat 5]
With --baseline, an older tinsmith binary runs too, interleaved with the new one and hmm
in every repeat, and its time ratio to hmm is printed beside the new one's (the machine is
shared: compare ratios within one run, not seconds across runs).
Times: tinsmith's is its decimation time from --report (initial mesh + decimation, not
file reading or writing); hmm's is the Delatin() call on an in-memory array. Each is the
best of --repeat runs.
"""
import argparse
import warnings
import json
import pathlib
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
import rasterio
from pydelatin import Delatin

warnings.filterwarnings("ignore", category=rasterio.errors.NotGeoreferencedWarning)

CASES = {
    "etopo5": ("dem/etopo5_global_5arcmin.tif", None),
    "bigtujunga": ("dem/topotoolbox_bigtujunga_30m.tif", None),
    "fuji": ("rgb/martini_fuji_terrainrgb_512.png", "mapbox"),
    "ct_head": ("scalar/mpl_ct_head_512x512_u16.png", None),
}


def load(path, decode):
    with rasterio.open(path) as ds:
        if decode == "mapbox":
            r, g, b = (ds.read(i).astype(np.float64) for i in (1, 2, 3))
            return -10000.0 + (r * 65536 + g * 256 + b) * 0.1
        return ds.read(1).astype(np.float64)


def write_tif(path, a):
    h, w = a.shape
    with rasterio.open(path, "w", driver="GTiff", width=w, height=h, count=1, dtype="float64") as ds:
        ds.write(a, 1)


def write_obj(path, vertices, triangles, height):
    # pydelatin's y axis points up (y = height - 1 - row); turn it into rows. Orientation is
    # a convention: make every triangle counter-clockwise in (column, row), as verify expects
    # for pixel coordinates.
    v = np.asarray(vertices, dtype=np.float64).copy()
    v[:, 1] = (height - 1) - v[:, 1]
    t = np.asarray(triangles, dtype=np.int64)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    t = np.where((cross < 0)[:, None], t[:, [0, 2, 1]], t)
    with open(path, "w") as f:
        for x, y, z in v:
            f.write(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n")
        for i, j, k in t + 1:
            f.write(f"f {i} {j} {k}\n")


def verify(binary, raster, mesh, eps):
    p = subprocess.run([binary, "verify", str(raster), str(mesh), "--pixel-coords", "--json",
                        "--max-error", str(eps)], capture_output=True, text=True)
    if not p.stdout:
        sys.exit(f"verify failed to run on {mesh}: {p.stderr}")
    return json.loads(p.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bin", default="target/release/tinsmith")
    ap.add_argument("--eps", default="0.5,1,5,30")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--tinsmith-args", default="")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--baseline", help="an older tinsmith binary to run interleaved")
    ap.add_argument("--out")
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    rows = ["| DEM | ε | triangles tinsmith / hmm | ratio | seconds tinsmith / hmm | ratio | hmm keeps | max error tinsmith / hmm | targets |",
            "|---|---|---|---|---|---|---|---|---|"]
    all_ok = True
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for name in args.cases.split(","):
            rel, decode = CASES[name]
            grid = load(data / rel, decode)
            raster = tmp / f"{name}.tif"
            write_tif(raster, grid)  # both tools see the same f64 samples
            h, w = grid.shape
            full = 2 * (w - 1) * (h - 1)
            hmm_in = grid.astype(np.float32)
            for eps in [float(e) for e in args.eps.split(",")]:
                # tinsmith (and the baseline), then hmm, alternately in each repeat
                best_t = best_b = best_h = None
                for _ in range(args.repeat):
                    for which in ([args.bin] + ([args.baseline] if args.baseline else [])):
                        out = tmp / ("t.ply" if which == args.bin else "b.ply")
                        rep = tmp / "t.json"
                        cmd = [which, "mesh", str(raster), "-o", str(out), "--max-error", str(eps),
                               "--pixel-coords", "-q", "--threads", "1", "--report", str(rep)] + shlex.split(args.tinsmith_args)
                        p = subprocess.run(cmd, capture_output=True, text=True)
                        if p.returncode != 0:
                            sys.exit(f"tinsmith failed: {p.stderr}")
                        rr = json.loads(rep.read_text())
                        s = rr["seconds"]["initial_mesh"] + rr["seconds"]["decimate"]
                        if which == args.bin:
                            best_t = s if best_t is None else min(best_t, s)
                            r = rr
                        else:
                            best_b = s if best_b is None else min(best_b, s)
                            b_tris = rr["triangles_after"]
                    t0 = time.perf_counter()
                    tin = Delatin(hmm_in, width=w, height=h, max_error=eps)
                    s = time.perf_counter() - t0
                    best_h = s if best_h is None else min(best_h, s)
                t_tris = r["triangles_after"]
                t_err = verify(args.bin, raster, tmp / "t.ply", eps)
                h_tris = len(tin.triangles)
                hobj = tmp / "h.obj"
                write_obj(hobj, tin.vertices, tin.triangles, h)
                h_err = verify(args.bin, raster, hobj, eps)
                keeps = h_tris / full
                tri_ratio = t_tris / h_tris
                time_ratio = best_t / best_h
                time_target = 0.2 if keeps > 0.30 else 1.0
                ok_tri = tri_ratio <= 0.85
                ok_time = time_ratio <= time_target
                ok_err = t_err["max_error"] <= eps and t_err["mesh_is_valid"] if "mesh_is_valid" in t_err else t_err["max_error"] <= eps
                ok = ok_tri and ok_time and ok_err
                base = (f" baseline {b_tris} triangles, {best_b:.3f} s = {best_b / best_h:.2f} x hmm;"
                        if args.baseline else "")
                all_ok &= ok
                rows.append(
                    f"| {name} {w}x{h} | {eps:g} | {t_tris} / {h_tris} | {tri_ratio:.2f} | "
                    f"{best_t:.3f} / {best_h:.3f} | {time_ratio:.2f} (≤ {time_target}) | {100 * keeps:.0f} % | "
                    f"{t_err['max_error']:.6g} / {h_err['max_error']:.6g} | "
                    f"{'tri ' + ('ok' if ok_tri else 'MISS')}, {'time ' + ('ok' if ok_time else 'MISS')}, {'err ' + ('ok' if ok_err else 'MISS')};{base} |")
                print(rows[-1], flush=True)
    table = "\n".join(rows) + "\n"
    if args.out:
        pathlib.Path(args.out).write_text(table)
    print()
    print(table)
    print("all targets met" if all_ok else "some targets missed")


if __name__ == "__main__":
    main()
