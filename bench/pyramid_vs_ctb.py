#!/usr/bin/env python3
"""Terrain pyramids against ctb: CPU, wall, peak memory, bytes and triangles of
cesium-terrain-builder's quantized-mesh fork (`ctb-tile -f Mesh`) and `tinsmith tiles` on
the same rasters and zoom ranges, one thread each, interleaved, in one run.

ctb is built from a local copy of its source (`--ctb PATH`: a checkout of
https://github.com/ahuarte47/cesium-terrain-builder, branch master-quantized-mesh) into
PATH/build-bench, with the one change it needs to build on GDAL 3.6 applied to a copy of
src/gdaloverviewdataset.cpp (GDAL 3.6 made `RefUnderlyingRasterBand` const and gave
`FlushCache` a `bAtClosing` argument; see bench/README-ctb.md). cmake, g++ and libgdal-dev
must be installed.

Usage:
    python3 bench/pyramid_vs_ctb.py --ctb ~/src/cesium-terrain-builder \
        [--tinsmith target/release/tinsmith] [--shared ../shared] [--repeat 3] \
        [--cases etopo5,bigtujunga,fortworth]
Prints a markdown table; ratios are tinsmith / ctb. The machine may be shared: read the
ratios, measured side by side, not the seconds.
"""
import argparse
import gzip
import json
import os
import pathlib
import re
import shutil
import statistics
import struct
import subprocess
import tempfile
import time

CASES = {
    "etopo5": ("dem/etopo5_global_5arcmin.tif", 4),
    "bigtujunga": ("dem/topotoolbox_bigtujunga_30m.tif", 12),
    "fortworth": ("dem/pysheds_dem_fortworth_3arcsec.tif", 10),
}

# The GDAL 3.6 signatures, as (pattern, replacement) on src/gdaloverviewdataset.cpp.
GDAL36 = [
    (r"GDALRasterBand\* RefUnderlyingRasterBand\(\) override;",
     "GDALRasterBand* RefUnderlyingRasterBand() const override;"),
    (r"CPLErr FlushCache\(\) override;", "CPLErr FlushCache(bool bAtClosing) override;"),
    (r"(?m)^CPLErr GDALOverviewBand::FlushCache\(\)$",
     "CPLErr GDALOverviewBand::FlushCache(bool bAtClosing)"),
    (r"return poUnderlyingBand->FlushCache\(\);", "return poUnderlyingBand->FlushCache(bAtClosing);"),
    (r"(?m)^GDALRasterBand\* GDALOverviewBand::RefUnderlyingRasterBand\(\)$",
     "GDALRasterBand* GDALOverviewBand::RefUnderlyingRasterBand() const"),
    (r"(?m)^    GDALOverviewDataset::FlushCache\(\);", "    GDALOverviewDataset::FlushCache(true);"),
    (r"(?m)^    GDALOverviewBand::FlushCache\(\);", "    GDALOverviewBand::FlushCache(true);"),
]


def build_ctb(source):
    """ctb-tile built from `source` (patched copy in source/build-bench/src)."""
    source = pathlib.Path(source).resolve()
    work = source / "build-bench"
    binary = work / "build" / "tools" / "ctb-tile"
    if binary.exists():
        return binary
    if (work / "src").exists():
        shutil.rmtree(work / "src")
    shutil.copytree(source, work / "src", ignore=shutil.ignore_patterns("build*", ".git"))
    overview = work / "src" / "src" / "gdaloverviewdataset.cpp"
    text = overview.read_text()
    for pattern, replacement in GDAL36:
        text = re.sub(pattern, replacement, text)
    overview.write_text(text)
    (work / "build").mkdir(parents=True, exist_ok=True)
    subprocess.run(["cmake", str(work / "src"), "-DCMAKE_BUILD_TYPE=Release"], cwd=work / "build",
                   check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["make", f"-j{os.cpu_count()}", "ctb-tile"], cwd=work / "build", check=True,
                   stdout=subprocess.DEVNULL)
    return binary


def timed(cmd):
    """Runs `cmd` under GNU time: (CPU seconds, wall seconds, peak RSS in MB)."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        start = time.perf_counter()
        subprocess.run(["/usr/bin/time", "-f", "%U %S %M", "-o", t.name, *cmd], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - start
        user, system, rss_kb = open(t.name).read().split()[-3:]
    return float(user) + float(system), wall, int(rss_kb) / 1024


def triangles(path):
    """The triangle count of a quantized-mesh tile (gzip or not)."""
    data = path.read_bytes()
    if data[:2] == b"\x1f\x8b":
        data = gzip.decompress(data)
    (vertices,) = struct.unpack_from("<I", data, 88)
    at = 92 + 6 * vertices
    wide = vertices > 65536
    align = 4 if wide else 2
    at += (-at) % align
    (count,) = struct.unpack_from("<I", data, at)
    return count


def pyramid(out):
    """(tiles, bytes, triangles) of the .terrain files under `out`."""
    files = sorted(out.rglob("*.terrain"))
    return len(files), sum(f.stat().st_size for f in files), sum(triangles(f) for f in files)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ctb", required=True, help="a checkout of ctb's quantized-mesh fork")
    ap.add_argument("--tinsmith", default="target/release/tinsmith")
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cases", default=",".join(CASES))
    args = ap.parse_args()
    ctb = build_ctb(args.ctb)
    data = pathlib.Path(args.shared) / "data"
    print("| pyramid | CPU s ctb / tinsmith | ratio | wall s ctb / tinsmith | peak MB ctb / tinsmith "
          "| tiles ctb / tinsmith | bytes ctb / tinsmith | ratio | triangles ctb / tinsmith | ratio "
          "| tinsmith max error / bound |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for name in args.cases.split(","):
            rel, zoom = CASES[name]
            raster = data / rel
            runs = {"ctb": [], "tinsmith": []}
            for _ in range(args.repeat):
                for which in ("ctb", "tinsmith"):
                    out = tmp / which
                    shutil.rmtree(out, ignore_errors=True)
                    out.mkdir()
                    if which == "ctb":
                        cmd = [str(ctb), "-f", "Mesh", "-C", "-c", "1", "-q", "-s", str(zoom),
                               "-e", "0", "-o", str(out), str(raster)]
                    else:
                        cmd = [args.tinsmith, "tiles", str(raster), "-o", str(out), "--max-zoom",
                               str(zoom), "--threads", "1", "-q", "--report", str(tmp / "r.json")]
                    runs[which].append(timed(cmd))
                    if which == "tinsmith":
                        report = json.loads((tmp / "r.json").read_text())
            med = {w: [statistics.median(r[i] for r in runs[w]) for i in range(3)] for w in runs}
            shape = {w: pyramid(tmp / w) for w in runs}
            levels = report.get("levels", [])
            worst = max((l.get("measured_max_error", 0) / l["bound"] for l in levels
                         if l.get("bound")), default=0)
            (c_cpu, c_wall, c_rss), (t_cpu, t_wall, t_rss) = med["ctb"], med["tinsmith"]
            (c_tiles, c_bytes, c_tris), (t_tiles, t_bytes, t_tris) = shape["ctb"], shape["tinsmith"]
            print(f"| {name} z0-{zoom} | {c_cpu:.2f} / {t_cpu:.2f} | {t_cpu / c_cpu:.2f} | "
                  f"{c_wall:.2f} / {t_wall:.2f} | {c_rss:.0f} / {t_rss:.0f} | {c_tiles} / {t_tiles} | "
                  f"{c_bytes:,} / {t_bytes:,} | {t_bytes / c_bytes:.2f} | {c_tris:,} / {t_tris:,} | "
                  f"{t_tris / c_tris:.2f} | {worst:.3f} |", flush=True)


if __name__ == "__main__":
    main()
