#!/usr/bin/env python3
"""The Python package against pydelatin (hmm's greedy insertion), in one process.

Same arrays (loaded as bench/compare.py loads them: ETOPO5, Big Tujunga, Fuji decoded from
terrain-RGB, the CT head slice), one thread each (`threads=1`; hmm has one), at each ε:
triangles, seconds of the call and the largest error of each, both errors measured by
`tinsmith.verify` against the float64 array (hmm's vertices turned into rows and its
triangles counter-clockwise, as compare.py does), and the peak memory each call added
over the array's own size (`VmHWM` of /proc/self/status, reset before each call through
/proc/self/clear_refs, less the resident size before the call; glibc told to mmap blocks
of 1 MiB and more and to trim its heap before each call, so that memory freed by an
earlier call does not hide the next one's). Then the binding's
per-call overhead on a 64x64 array: the call's wall time less the engine's own seconds
(initial mesh, decimation, verification) from its report, median of many calls.

Usage (make bench-python installs pydelatin and rasterio, and the package):
    .venv/bin/python bench/python_vs_pydelatin.py [--shared ../shared] [--eps 0.5,1,5,30]
        [--cases etopo5,bigtujunga,fuji,ct_head] [--out FILE.md]
"""
import argparse
import ctypes
import pathlib
import statistics
import sys
import time

import numpy as np
from pydelatin import Delatin

import tinsmith

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from compare import CASES, load  # noqa: E402  (the loading of the CLI-vs-hmm bench)


def rss_bytes(field):
    for line in open("/proc/self/status"):
        if line.startswith(field):
            return int(line.split()[1]) * 1024
    raise RuntimeError(f"no {field} in /proc/self/status")


LIBC = ctypes.CDLL("libc.so.6")
# glibc: large blocks always mmapped (no dynamic threshold), so what a call frees goes
# back to the system and the next call's peak is its own, not hidden in reused heap.
LIBC.mallopt(-3, 1 << 20)  # M_MMAP_THRESHOLD = 1 MiB


def peak_over(call):
    """Runs `call`; returns its result, its seconds and the peak resident memory it added."""
    LIBC.malloc_trim(0)  # the heap's free pages back to the system first
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # resets VmHWM to the current resident size
    before = rss_bytes("VmRSS:")
    t = time.perf_counter()
    result = call()
    seconds = time.perf_counter() - t
    return result, seconds, max(0, rss_bytes("VmHWM:") - before)


def hmm_mesh(vertices, triangles, rows):
    """hmm's vertices (y up: y = rows - 1 - row) as (column, row, z), its triangles made
    counter-clockwise in (column, row) as tinsmith's pixel-coordinate meshes are."""
    v = np.asarray(vertices, dtype=np.float64).copy()
    v[:, 1] = (rows - 1) - v[:, 1]
    t = np.asarray(triangles, dtype=np.int64)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    return v, np.where((cross < 0)[:, None], t[:, [0, 2, 1]], t)


def overhead(repeat=300):
    y, x = np.mgrid[0:64, 0:64]
    a = 20 * np.sin(x / 7.0) * np.cos(y / 5.0)
    walls, engines = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        tin = tinsmith.mesh(a, 0.5)
        walls.append(time.perf_counter() - t)
        s = tin.report["seconds"]
        engines.append(s["initial_mesh"] + s["decimate"] + s["verify"])
    wall, engine = statistics.median(walls), statistics.median(engines)
    return wall, engine, statistics.median(w - e for w, e in zip(walls, engines))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--eps", default="0.5,1,5,30")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--out")
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    rows = [
        "| array | ε | triangles tinsmith / hmm | ratio | seconds tinsmith / hmm | ratio | "
        "max error tinsmith / hmm | peak memory / array, tinsmith / hmm |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in args.cases.split(","):
        rel, decode = CASES[name]
        grid = load(data / rel, decode)  # float64, as both get it
        h, w = grid.shape
        hmm_in = grid.astype(np.float32)  # pydelatin computes in float32 (as compare.py)
        for eps in [float(e) for e in args.eps.split(",")]:
            tin, t_s, t_mem = peak_over(lambda: tinsmith.mesh(grid, eps, threads=1))
            hmm, h_s, h_mem = peak_over(lambda: Delatin(hmm_in, width=w, height=h, max_error=eps))
            hv, ht = hmm_mesh(hmm.vertices, hmm.triangles, h)
            h_err = tinsmith.verify(grid, hv, ht)["max_error"]
            t_n, h_n = len(tin), len(ht)
            rows.append(
                f"| {name} {w}x{h} | {eps:g} | {t_n:,} / {h_n:,} | {t_n / h_n:.2f} | "
                f"{t_s:.3f} / {h_s:.3f} | {t_s / h_s:.2f} | {tin.max_error:.6g} / {h_err:.6g} | "
                f"{t_mem / grid.nbytes:.2f} / {h_mem / grid.nbytes:.2f} |"
            )
            print(rows[-1], flush=True)
            del tin, hmm, hv, ht
    wall, engine, over = overhead()
    table = "\n".join(rows) + "\n\n" + (
        f"Per call on a 64x64 float64 array at ε = 0.5 (median of 300): {1e3 * wall:.3f} ms in all, "
        f"{1e3 * engine:.3f} ms in the engine (initial mesh, decimation, verification), "
        f"**{1e3 * over:.3f} ms binding overhead** (target < 1 ms).\n"
    )
    if args.out:
        pathlib.Path(args.out).write_text(table)
    print()
    print(table)


if __name__ == "__main__":
    main()
