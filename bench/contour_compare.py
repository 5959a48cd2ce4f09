#!/usr/bin/env python3
"""Contours from tinsmith's TIN versus gdal_contour on the full grid (paper section 5).

For each DEM: the same explicit levels (offset + k * interval over the raster's range) go
to `gdal_contour -fl ...` (Debian gdal-bin, marching squares on the full grid) and to
`tinsmith contour --levels ...` at several max errors (0 = the full grid, two triangles
per cell; then decimated TINs), in the same run. Reported per run:

- seconds: wall clock of the whole command (read, decimate, contour, write), median of
  --repeat runs, writing FlatGeobuf (.fgb) and, separately, GeoJSON (both tools in the
  raster's CRS: tinsmith with --geojson-source-crs);
- lines, segments (points - 1 summed over lines) and total length, from the GeoJSON;
- Hausdorff distance to gdal_contour's lines of the same level, maximized over levels,
  and the 99th percentile of the sampled distances (both directions, all levels).

Hausdorff method (stdlib only): for each level, every vertex and every segment midpoint
of one line set is a sample point; its distance to the nearest *segment* of the other
set is found through a uniform grid of buckets (exact point-to-segment distance). The
directed distances are maxima over the samples, the Hausdorff distance is the larger of
the two directions. Sampling at vertices and midpoints underestimates the true value by
at most half the longest segment's length (reported as `sample gap`). A level present in
only one output (a small feature one side missed) counts as the largest distance from
its lines to any point of the other set's lines at any level; such levels are listed.
gdal_contour also writes microscopic rings (length below a thousandth of a pixel) around
single samples exactly at a level (its 1e-6 nudge of such values); tinsmith drops lines
that collapse to a point, so these are left out of gdal's lines (simplified or not),
segments and Hausdorff distance and counted in a note.

Also reported: `tinsmith contour --mesh` on a TIN written beforehand by `tinsmith mesh`
(decimation paid once, contouring many times: the paper's interactive use); and, at
ε = interval / 10, `tinsmith contour --simplify D` (Douglas-Peucker within D map units;
no longer exact contours of the TIN) beside gdal_contour's lines simplified by
`ogr2ogr -simplify D` (GEOS, topology-preserving per line), at D = 0.1 and 0.25 pixel;
the ogr2ogr time is its own, written to GeoJSON from gdal_contour's FlatGeobuf.

Usage (from the repository root, after `cargo build --release`):

    python3 bench/contour_compare.py [--shared ../shared] [--repeat 3] [--out FILE.md]
"""
import argparse
import json
import math
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

CASES = [
    # (label, path under shared/data, interval, [max errors])
    ("Big Tujunga, SRTM 30 m, 1197x643", "dem/topotoolbox_bigtujunga_30m.tif", 50, None),
    ("BC TRIM 50 m (becmodel), 430x516", "dem/becmodel_dem_bc_albers_50m.tif", 100, None),
    ("ETOPO5, 5', 4320x2161", "dem/etopo5_global_5arcmin.tif", 1000, [0, 100]),
]


# tinsmith writes GeoJSON in WGS84 by default (RFC 7946); gdal_contour writes the raster's
# CRS. Both in the raster's CRS: the same work, and distances in map units.
SRC_CRS = ["--geojson-source-crs"]
# `tinsmith contour --simplify D` at ε = interval / 10, with D these fractions of a pixel;
# beside it, gdal_contour's lines simplified by `ogr2ogr -simplify D`.
SIMPLIFY = [0.1, 0.25]


def run(cmd):
    t = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return dt, p


def timed(cmd, repeat):
    return statistics.median(run(cmd)[0] for _ in range(repeat))


def raster_range(path, binary):
    _, p = run([binary, "info", str(path), "--json"])
    info = json.loads(p.stdout)
    return info["min"], info["max"], info["geo_transform"]


def read_lines(path, west=None):
    """Lines by level. With `west` (the raster's left edge), x below it is moved a turn
    east and a MultiLineString's parts are joined: tinsmith's WGS84 GeoJSON wraps
    longitudes into [-180, 180] and cuts lines at the antimeridian (RFC 7946), so a raster
    on 0..360 (ETOPO5) is compared with gdal_contour in the raster's own frame."""
    by_level = {}
    for f in json.loads(pathlib.Path(path).read_text())["features"]:
        g = f["geometry"]
        parts = g["coordinates"] if g["type"] == "MultiLineString" else [g["coordinates"]]
        pts = []
        for part in parts:
            for x, y, *rest in part:
                if west is not None and x < west:
                    x += 360.0
                if not pts or pts[-1] != [x, y]:
                    pts.append([x, y])
        by_level.setdefault(float(f["properties"]["elev"]), []).append(pts)
    return by_level


def without_microscopic_rings(by_level, cell):
    """gdal_contour's lines without those shorter than cell / 2000, and how many."""
    kept, micro = {}, 0
    for level, lines in by_level.items():
        keep = [p for p in lines if sum(math.dist(a, b) for a, b in zip(p, p[1:])) >= cell / 2000]
        micro += len(lines) - len(keep)
        if keep:
            kept[level] = keep
    return kept, micro


def stats(by_level):
    lines = sum(len(v) for v in by_level.values())
    segs = sum(len(p) - 1 for v in by_level.values() for p in v)
    length = sum(math.dist(a, b) for v in by_level.values() for p in v for a, b in zip(p, p[1:]))
    return lines, segs, length


def seg_dist(p, a, b):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    px, py = p[0] - ax, p[1] - ay
    dd = dx * dx + dy * dy
    t = 0.0 if dd == 0 else max(0.0, min(1.0, (px * dx + py * dy) / dd))
    return math.hypot(px - t * dx, py - t * dy)


class SegmentIndex:
    """Uniform grid of buckets over segments; nearest-segment distance queries."""

    def __init__(self, lines, cell):
        self.cell = cell
        self.buckets = {}
        for p in lines:
            for a, b in zip(p, p[1:]):
                x0, x1 = sorted((a[0], b[0]))
                y0, y1 = sorted((a[1], b[1]))
                for i in range(int(math.floor(x0 / cell)), int(math.floor(x1 / cell)) + 1):
                    for j in range(int(math.floor(y0 / cell)), int(math.floor(y1 / cell)) + 1):
                        self.buckets.setdefault((i, j), []).append((a, b))

    def nearest(self, p):
        if not self.buckets:
            return math.inf
        ci, cj = int(math.floor(p[0] / self.cell)), int(math.floor(p[1] / self.cell))
        best = math.inf
        r = 0
        while True:
            for i in range(ci - r, ci + r + 1):
                for j in (range(cj - r, cj + r + 1) if i in (ci - r, ci + r) else (cj - r, cj + r)):
                    for a, b in self.buckets.get((i, j), ()):
                        d = seg_dist(p, a, b)
                        if d < best:
                            best = d
            # Every segment not yet seen is at least r cells away.
            if best <= r * self.cell or r > 4096:
                return best
            r += 1


def samples(lines):
    for p in lines:
        yield from p
        for a, b in zip(p, p[1:]):
            yield ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)


def directed(a_lines, index, dists):
    d = [index.nearest(p) for p in samples(a_lines)]
    dists.extend(d)
    return max(d, default=0.0)


def hausdorff(a, b, cell):
    """Max over levels of the Hausdorff distance between a[level] and b[level]."""
    worst, gap, missing, dists = 0.0, 0.0, [], []
    all_a = [p for v in a.values() for p in v]
    all_b = [p for v in b.values() for p in v]
    for side in (a, b):
        for v in side.values():
            for p in v:
                for s, t in zip(p, p[1:]):
                    gap = max(gap, math.dist(s, t) / 2)
    for level in sorted(set(a) | set(b)):
        la, lb = a.get(level, []), b.get(level, [])
        if la and lb:
            d = max(directed(la, SegmentIndex(lb, cell), dists), directed(lb, SegmentIndex(la, cell), dists))
        else:
            missing.append(level)
            only, other = (la, all_b) if la else (lb, all_a)
            d = directed(only, SegmentIndex(other, cell), dists)
        worst = max(worst, d)
    dists.sort()
    p99 = dists[int(0.99 * (len(dists) - 1))] if dists else 0.0
    return worst, gap, missing, p99


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bin", default="target/release/tinsmith")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", help="run only cases whose file name contains this")
    ap.add_argument("--out")
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    out = []
    emit = lambda s="": (print(s, flush=True), out.append(s))
    emit("| data | interval | source | ε | triangles | seconds .fgb | seconds .geojson | lines | segments | segments vs gdal | total length | Hausdorff to gdal |")
    emit("|---|---|---|---|---|---|---|---|---|---|---|---|")
    notes = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for label, rel, interval, eps in CASES:
            if args.only and args.only not in rel:
                continue
            src = data / rel
            if not src.exists():
                sys.exit(f"{src}: missing; pass --shared DIR")
            eps = eps or [0, interval / 20, interval / 10, interval / 5]
            lo, hi, gt = raster_range(src, args.bin)
            levels = [k * interval for k in range(math.ceil(lo / interval), math.floor(hi / interval) + 1)]
            levels = [l for l in levels if lo < l <= hi]
            lv = ",".join(f"{l:g}" for l in levels)
            pixel = abs(gt[1])
            cell = 2 * max(abs(gt[1]), abs(gt[5]))

            g_fgb, g_json = tmp / "g.fgb", tmp / "g.geojson"
            gcmd = ["gdal_contour", "-q", "-a", "elev", "-fl", *[f"{l:g}" for l in levels], str(src)]
            for f in (g_fgb, g_json):
                f.unlink(missing_ok=True)
            t_fgb = statistics.median(run(gcmd + [str(g_fgb)])[0] for _ in range(args.repeat) if not g_fgb.unlink(missing_ok=True))
            t_json = statistics.median(run(gcmd + [str(g_json)])[0] for _ in range(args.repeat) if not g_json.unlink(missing_ok=True))
            gdal, micro = without_microscopic_rings(read_lines(g_json), cell)
            if micro:
                notes.append(f"{label}: {micro} microscopic gdal_contour rings around single samples at a level left out")
            gl, gs, glen = stats(gdal)
            emit(f"| {label} | {interval} | gdal_contour (full grid) | – | – | {t_fgb:.2f} | {t_json:.2f} | {gl} | {gs} | – | {glen:.4g} | – |")

            for e in eps:
                t_out_fgb, t_out_json = tmp / "t.fgb", tmp / "t.geojson"
                base = [args.bin, "contour", str(src), "--levels", lv, "--max-error", f"{e:g}", "-q"]
                tf = timed(base + ["-o", str(t_out_fgb)], args.repeat)
                tj = timed(base + ["-o", str(t_out_json), *SRC_CRS], args.repeat)
                _, p = run([args.bin, "contour", str(src), "--levels", lv, "--max-error", f"{e:g}", "-o", str(t_out_json), *SRC_CRS])
                tris = p.stderr.split("(")[-1].split(" triangles")[0]
                tin = read_lines(t_out_json, gt[0])
                tl, ts, tlen = stats(tin)
                h, gap, missing, p99 = hausdorff(tin, gdal, cell)
                src_name = "tinsmith, full grid" if e == 0 else "tinsmith, TIN"
                emit(f"| {label} | {interval} | {src_name} | {e:g} | {tris} | {tf:.2f} | {tj:.2f} | {tl} | {ts} | {100 * (ts / gs - 1):+.0f} % | {tlen:.4g} | {h:.4g} (gap ≤ {gap:.2g}); 99 %: {p99:.3g} |")
                if missing:
                    notes.append(f"{label}, ε = {e:g}: levels on one side only: {missing}")
                if e == interval / 10:
                    mesh = tmp / "m.ply"
                    tm = timed([args.bin, "mesh", str(src), "-o", str(mesh), "--max-error", f"{e:g}", "--contour-levels", lv, "-q"], 1)
                    tmf = timed([args.bin, "contour", str(src), "--levels", lv, "--mesh", str(mesh), "-q", "-o", str(t_out_fgb)], args.repeat)
                    tmj = timed([args.bin, "contour", str(src), "--levels", lv, "--mesh", str(mesh), "-q", "-o", str(t_out_json), *SRC_CRS], args.repeat)
                    emit(f"| {label} | {interval} | tinsmith --mesh (TIN made once by `tinsmith mesh --contour-levels` in {tm:.2f} s) | {e:g} | {tris} | {tmf:.2f} | {tmj:.2f} | {tl} | {ts} | {100 * (ts / gs - 1):+.0f} % | {tlen:.4g} | same lines |")
                    for frac in SIMPLIFY:
                        d = frac * pixel
                        simp = ["--simplify", f"{d:g}"]
                        tsf = timed(base + simp + ["-o", str(t_out_fgb)], args.repeat)
                        tsj = timed(base + simp + ["-o", str(t_out_json), *SRC_CRS], args.repeat)
                        sl, ss, slen = stats(read_lines(t_out_json, gt[0]))
                        h, gap, _, p99 = hausdorff(read_lines(t_out_json, gt[0]), gdal, cell)
                        emit(f"| {label} | {interval} | tinsmith --simplify {d:g} ({frac:g} pixel) | {e:g} | {tris} | {tsf:.2f} | {tsj:.2f} | {sl} | {ss} | {100 * (ss / gs - 1):+.0f} % | {slen:.4g} | {h:.4g} (gap ≤ {gap:.2g}); 99 %: {p99:.3g} |")
                        # The same simplification (GEOS, topology-preserving per line) on
                        # gdal_contour's lines: gdal_contour, then ogr2ogr.
                        g_simp = tmp / "gs.geojson"
                        ocmd = ["ogr2ogr", "-simplify", f"{d:g}", str(g_simp), str(g_fgb)]
                        to = statistics.median(run(ocmd)[0] for _ in range(args.repeat) if not g_simp.unlink(missing_ok=True))
                        gsimp, _ = without_microscopic_rings(read_lines(g_simp), cell)
                        ol, os_, olen = stats(gsimp)
                        h, gap, _, p99 = hausdorff(gsimp, gdal, cell)
                        emit(f"| {label} | {interval} | gdal_contour + `ogr2ogr -simplify {d:g}` | – | – | {t_fgb:.2f} + {to:.2f} | – | {ol} | {os_} | {100 * (os_ / gs - 1):+.0f} % | {olen:.4g} | {h:.4g} (gap ≤ {gap:.2g}); 99 %: {p99:.3g} |")
    for n in notes:
        emit(f"- {n}")
    if args.out:
        pathlib.Path(args.out).write_text("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
