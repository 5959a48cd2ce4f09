#!/usr/bin/env python3
"""Benchmark of the tiled engine: wall time, samples/s, peak RSS and the ratios.

Builds Float32 DEMs from real data (ETOPO5, resampled with GDAL's gdalwarp, cubic) in a
work directory outside the repository (never committed), runs `tinsmith mesh` on them
under /usr/bin/time, and prints a Markdown report (also written to --out):

  main      16384^2 at eps = 1 m with the defaults (exact error, default start, default tile
            size), --threads 1 and 2: wall time, samples/s, peak RSS, CPU seconds; speedup
            of 2 threads over 1 (target >= 1.8x), end to end <= 60 s on 2 cores, peak RSS
            <= 1.5 GB.
  ratio     triangles tiled / untiled on DEMs that fit untiled (target <= 1.05x):
            bigtujunga 30 m and ETOPO5 itself, both error models.
  scaling   time per sample from 1024^2 to 16384^2 (target within +-20 %), 1 thread (so a
            raster that fits one tile is not penalised for running on one core): nested
            crops of the 16384^2 DEM, all centred on the same point, so resolution is the
            same at every size, though the content is not (the 16384^2 run is main's when
            main runs in the same invocation; --scaling-sizes picks the sizes).
  mosaic    time per sample from 1024^2 to 16384^2 on inputs of the same content: the
            centred 1024^2 crop repeated side by side (a GDAL VRT, translated to a tiled
            GeoTIFF), so every size has the same terrain per sample; 1 thread, as scaling.
  sizes     tile size sweep on a 4096^2 crop (how the default was chosen), 1 thread,
            defaults otherwise.
  shapes    time per sample on narrow rasters against a square one of as many samples
            (2 x 2,000,000 and 16 x 250,000 against 2000^2), in tiles of 512 and 8192, on
            a tilted plane and on flat ground (where whole tile borders are skipped), 1
            thread: the ratio narrow / square in CPU seconds per sample (every sample of
            a 2-wide raster is on a tile border).

Usage (from the repository root; GDAL command-line tools from Debian's gdal-bin):
    cargo build --release
    python3 bench/tiles.py [--shared ../shared] [--work /tmp/tinsmith-bench]
        [--sections main,ratio,scaling,mosaic,sizes,shapes] [--repeat 1] [--out FILE.md]

The machine is shared: each run records its CPU seconds (user + sys) beside the wall
time, and the load average before it, so that contention shows. With --repeat N the
fastest of N runs is kept.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

EPS = 1.0


def sh(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return p.stdout


def build_dem(shared, work, size):
    """The etopo5 global grid resampled to size x size Float32 (tiled GeoTIFF)."""
    path = work / f"etopo5_{size}.tif"
    if not path.exists():
        src = shared / "data/dem/etopo5_global_5arcmin.tif"
        sh(["gdalwarp", "-q", "-overwrite", "-ts", str(size), str(size), "-r", "cubic",
            "-ot", "Float32", "-co", "TILED=YES", "-co", "BIGTIFF=IF_SAFER", str(src),
            str(path)])
    return path


def crop(work, big, big_size, size):
    """A size x size window centred in the big DEM."""
    path = work / f"crop_{size}_of_{big_size}.tif"
    if not path.exists():
        off = (big_size - size) // 2
        sh(["gdal_translate", "-q", "-srcwin", str(off), str(off), str(size), str(size),
            "-co", "TILED=YES", str(big), str(path)])
    return path


def mosaic(work, tile, tile_size, size):
    """A size x size Float32 GeoTIFF holding the tile_size^2 raster `tile` repeated."""
    if size == tile_size:
        return tile
    path = work / f"mosaic_{size}_of_{tile_size}.tif"
    if not path.exists():
        n = size // tile_size
        sources = "".join(
            f'<SimpleSource><SourceFilename relativeToVRT="0">{tile}</SourceFilename>'
            f'<SourceBand>1</SourceBand>'
            f'<SrcRect xOff="0" yOff="0" xSize="{tile_size}" ySize="{tile_size}"/>'
            f'<DstRect xOff="{i * tile_size}" yOff="{j * tile_size}" xSize="{tile_size}" '
            f'ySize="{tile_size}"/></SimpleSource>'
            for j in range(n) for i in range(n))
        vrt = work / f"mosaic_{size}.vrt"
        vrt.write_text(
            f'<VRTDataset rasterXSize="{n * tile_size}" rasterYSize="{n * tile_size}">'
            f'<GeoTransform>0, 1, 0, {n * tile_size}, 0, -1</GeoTransform>'
            f'<VRTRasterBand dataType="Float32" band="1">{sources}</VRTRasterBand>'
            f'</VRTDataset>')
        sh(["gdal_translate", "-q", "-co", "TILED=YES", "-co", "BIGTIFF=IF_SAFER", str(vrt),
            str(path)])
        vrt.unlink()
    return path


def synthetic(work, name, width, height, value):
    """A Float32 ESRI .hdr/.bil raster of `value(x, y)` (stdlib only), 1 unit per sample."""
    import array
    path = work / f"{name}_{width}x{height}.bil"
    if not path.exists():
        with open(path, "wb") as f:
            for y in range(height):
                array.array("f", (value(x, y) for x in range(width))).tofile(f)
        (work / f"{name}_{width}x{height}.hdr").write_text(
            f"BYTEORDER I\nLAYOUT BIL\nNROWS {height}\nNCOLS {width}\nNBANDS 1\n"
            "NBITS 32\nPIXELTYPE FLOAT\nULXMAP 0.5\nULYMAP -0.5\nXDIM 1\nYDIM 1\n")
    return path


def load():
    return os.getloadavg()[0]


def mesh(binary, dem, work, extra, repeat):
    """Runs tinsmith mesh; returns the best run's wall, cpu, rss (MB) and report."""
    best = None
    for _ in range(repeat):
        out = work / "out.ply"
        report = work / "report.json"
        timing = work / "time.txt"
        before = load()
        cmd = ["/usr/bin/time", "-f", "%e %U %S %M", "-o", str(timing), str(binary), "mesh",
               str(dem), "-o", str(out), "--max-error", str(EPS), "--report", str(report),
               "-q"] + extra
        sh(cmd)
        wall, user, sys_, rss = open(timing).read().split()[-4:]
        r = json.load(open(report))
        run = {
            "wall": float(wall),
            "cpu": float(user) + float(sys_),
            "rss_mb": int(rss) / 1024,
            "load_before": before,
            "report": r,
        }
        out.unlink()
        if best is None or run["wall"] < best["wall"]:
            best = run
    return best


def samples(r):
    return r["report"]["width"] * r["report"]["height"]


def row(label, r, extra=""):
    rep = r["report"]
    tiles = rep.get("tiles")
    tiling = f"{tiles['count']} x {tiles['size']}" if tiles else "untiled"
    return (f"| {label} | {tiling} | {r['wall']:.1f} | {r['cpu']:.1f} | "
            f"{samples(r) / r['wall'] / 1e6:.2f} | {r['rss_mb']:.0f} | "
            f"{rep['triangles_after']:,} | {rep['measured_max_error']:.4g} | "
            f"{r['load_before']:.1f} |{extra}")


HEADER = ("| run | tiles | wall s | CPU s | M samples/s | peak RSS MB | triangles | "
          "max error | load before |")
RULE = "|---|---|---|---|---|---|---|---|---|"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--work", default="/tmp/tinsmith-bench")
    ap.add_argument("--bin", default="target/release/tinsmith")
    ap.add_argument("--sections", default="main,ratio,scaling,mosaic,sizes,shapes")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--scaling-sizes", default="1024,2048,4096,8192,16384")
    ap.add_argument("--out")
    args = ap.parse_args()
    shared, work = pathlib.Path(args.shared), pathlib.Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    binary = pathlib.Path(args.bin).resolve()
    sections = args.sections.split(",")
    lines = [f"Machine: {os.cpu_count()} cores; eps = {EPS} m; "
             f"{time.strftime('%Y-%m-%d %H:%M')}.", ""]

    def emit(text=""):
        print(text, flush=True)
        lines.append(text)

    big_size = 16384
    uses_big = {"main", "scaling", "mosaic", "sizes"} & set(sections)
    big = build_dem(shared, work, big_size) if uses_big else None

    one = two = None
    if "main" in sections:
        emit(f"### 16384 x 16384 Float32 (ETOPO5 resampled), eps = {EPS} m")
        emit()
        emit(HEADER)
        emit(RULE)
        one = mesh(binary, big, work, ["--threads", "1"], args.repeat)
        emit(row("defaults, 1 thread", one))
        two = mesh(binary, big, work, ["--threads", "2"], args.repeat)
        emit(row("defaults, 2 threads", two))
        emit()
        emit(f"- speedup 2 threads / 1: {one['wall'] / two['wall']:.2f}x (target >= 1.8x)")
        emit(f"- end to end on 2 cores: {two['wall']:.1f} s (target <= 60 s)")
        emit(f"- peak RSS: {two['rss_mb']:.0f} MB with 2 threads, {one['rss_mb']:.0f} MB "
             f"with 1 (target <= 1536 MB)")
        emit()

    if "ratio" in sections:
        emit("### Triangles tiled / untiled (DEMs that fit untiled)")
        emit()
        emit(HEADER + " tiled / untiled |")
        emit(RULE + "---|")
        cases = [("bigtujunga 30 m", shared / "data/dem/topotoolbox_bigtujunga_30m.tif",
                  ["256", "128"]),
                 ("ETOPO5 4320 x 2161", shared / "data/dem/etopo5_global_5arcmin.tif",
                  ["1024", "256"])]
        for label, dem, sizes in cases:
            for model in ["bounds", "exact"]:
                base = ["--threads", "2", "--error-model", model]
                untiled = mesh(binary, dem, work, base + ["--tile-size", "100000"], 1)
                emit(row(f"{label}, {model}", untiled, " 1 |"))
                for size in sizes:
                    tiled = mesh(binary, dem, work, base + ["--tile-size", size], 1)
                    ratio = (tiled["report"]["triangles_after"]
                             / untiled["report"]["triangles_after"])
                    emit(row(f"{label}, {model}", tiled, f" {ratio:.4f} |"))
        emit()

    if "scaling" in sections:
        emit("### Time per sample, nested centred crops of the 16384^2 DEM, 1 thread")
        emit()
        emit(HEADER + " us / sample | vs 16384^2 |")
        emit(RULE + "---|---|")
        runs = []
        for size in [int(s) for s in args.scaling_sizes.split(",")]:
            if size == big_size and one is not None:
                runs.append(one)
                continue
            dem = big if size == big_size else crop(work, big, big_size, size)
            runs.append(mesh(binary, dem, work, ["--threads", "1"], args.repeat))
        ref = runs[-1]["wall"] / samples(runs[-1])
        for r in runs:
            per = r["wall"] / samples(r)
            emit(row(f"{r['report']['width']}^2", r, f" {per * 1e6:.3f} | {per / ref:.2f} |"))
        emit()

    if "mosaic" in sections:
        emit("### Time per sample on the same content: the centred 1024^2 crop repeated, "
             "1 thread")
        emit()
        emit(HEADER + " us / sample | vs 1024^2 |")
        emit(RULE + "---|---|")
        tile = crop(work, big, big_size, 1024)
        ref = None
        for size in [int(s) for s in args.scaling_sizes.split(",")]:
            dem = mosaic(work, tile, 1024, size)
            r = mesh(binary, dem, work, ["--threads", "1"], args.repeat)
            per = r["wall"] / samples(r)
            ref = ref or per
            emit(row(f"{r['report']['width']}^2", r, f" {per * 1e6:.3f} | {per / ref:.2f} |"))
            if dem != tile:
                dem.unlink()
        emit()

    if "sizes" in sections:
        emit("### Tile size, 4096^2 centred crop, 1 thread")
        emit()
        emit(HEADER)
        emit(RULE)
        dem = crop(work, big, big_size, 4096)
        for size in ["128", "256", "512", "1024", "2048", "4096"]:
            r = mesh(binary, dem, work, ["--threads", "1", "--tile-size", size], args.repeat)
            emit(row(f"--tile-size {size}", r))
        emit()

    if "shapes" in sections:
        emit("### Narrow rasters against a square one of as many samples, 1 thread")
        emit()
        emit(HEADER + " CPU us / sample | vs square |")
        emit(RULE + "---|---|")
        grounds = {"plane": lambda x, y: 0.01 * x + 0.02 * y, "flat": lambda x, y: 0.0}
        for ground, value in grounds.items():
            for tile_size in ["512", "8192"]:
                ref = None
                for width, height in [(2000, 2000), (2_000_000, 2), (250_000, 16)]:
                    dem = synthetic(work, ground, width, height, value)
                    extra = ["--threads", "1", "--tile-size", tile_size]
                    r = mesh(binary, dem, work, extra, args.repeat)
                    # CPU time: one thread, and robust to other work on the machine.
                    per = r["cpu"] / samples(r)
                    ref = ref or per
                    emit(row(f"{ground} {width} x {height}", r,
                             f" {per * 1e6:.3f} | {per / ref:.2f} |"))
        emit()

    if args.out:
        pathlib.Path(args.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
