#!/usr/bin/env python3
"""CPU seconds of `tinsmith tiles` for two binaries, interleaved in one run.

For each pyramid (ETOPO5 levels 0-4, Big Tujunga 0-12, Fort Worth 3" 0-10) runs the
`--before` and `--after` binaries alternately, `--repeat` times each, one thread, and
prints the median user+system CPU seconds of each, their ratio, tiles, bytes, triangles
and the largest measured error against the source over the per-tile bound (from
--report). Ratios are what to read: the machine is shared.

Usage:
    python3 bench/pyramid_cpu.py --before OLD_BINARY --after target/release/tinsmith \
        [--shared ../shared] [--repeat 3] [--cases etopo5,bigtujunga,fortworth]
"""
import argparse
import json
import os
import pathlib
import resource
import shutil
import statistics
import subprocess
import tempfile

CASES = {
    "etopo5": ("dem/etopo5_global_5arcmin.tif", 4),
    "bigtujunga": ("dem/topotoolbox_bigtujunga_30m.tif", 12),
    "fortworth": ("dem/pysheds_dem_fortworth_3arcsec.tif", 10),
}


def run(binary, raster, zoom, out):
    shutil.rmtree(out, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    report = out.with_suffix(".json")
    subprocess.run([binary, "tiles", str(raster), "-o", str(out), "--max-zoom", str(zoom),
                    "--threads", "1", "-q", "--report", str(report)], check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    size = sum(f.stat().st_size for f in out.rglob("*.terrain"))
    return cpu, size, json.loads(report.read_text())


def summary(report):
    levels = report.get("levels", [])
    tris = sum(l.get("triangles", 0) for l in levels)
    tiles = sum(l.get("tiles", 0) for l in levels)
    worst = max((l.get("measured_max_error", 0) / l["bound"] for l in levels if l.get("bound")), default=0)
    return tiles, tris, worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", default="target/release/tinsmith")
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cases", default=",".join(CASES))
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    print("| pyramid | CPU s before | after | after / before | tiles | triangles before / after | bytes before / after | max error / bound after |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for name in args.cases.split(","):
            rel, zoom = CASES[name]
            cpu = {"before": [], "after": []}
            last = {}
            for _ in range(args.repeat):
                for which in ("before", "after"):
                    c, size, rep = run(getattr(args, which), data / rel, zoom, tmp / which)
                    cpu[which].append(c)
                    last[which] = (size, rep)
            b, a = statistics.median(cpu["before"]), statistics.median(cpu["after"])
            tb, trb, _ = summary(last["before"][1])
            ta, tra, wa = summary(last["after"][1])
            print(f"| {name} z0-{zoom} | {b:.2f} | {a:.2f} | {a / b:.2f} | {tb} / {ta} | {trb} / {tra} | "
                  f"{last['before'][0]} / {last['after'][0]} | {wa:.3f} |", flush=True)


if __name__ == "__main__":
    main()
