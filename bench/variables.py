#!/usr/bin/env python3
"""Several variables over one mesh (`tinsmith mesh --bands`): decimation and time against
the single-variable meshes and the correlation between the variables.

On the heart's 16 MR frames (../shared/data/scalar/mr_heart_256x256_u8_16frames.tif) the
first 1, 2, 4, 8 and 16 frames are meshed together at ε = 4, 8, 16 (every frame within ε),
and each frame alone; on the CODEM DSM pair (../shared/data/dem/codem_*.tif) the two
rasters are put on one grid in a temporary VRT (gdalbuildvrt -separate) and meshed
together and alone. Every joint mesh is checked again by `tinsmith verify --bands`.

Time per sample is decimation time (start + removals, from `--report`) over the samples,
the best of --repeat interleaved runs, as a ratio to the single-variable run (the first
band alone) measured in the same run; time per output triangle divides by each run's
triangles instead. Correlations are Pearson's over the samples valid in every band, of
the values and of their 5-point Laplacians (the detail a plane does not follow). Usage (from the repository root):

    python3 bench/variables.py [--shared ../shared] [--bin target/release/tinsmith] [--out FILE]
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

HEART = "scalar/mr_heart_256x256_u8_16frames.tif"
CODEM_DSM = "dem/codem_aoi_dsm_1m.tif"
CODEM_DEM = "dem/codem_dem_1m.tif"


def run(cmd):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return p.stdout


def bands_as_arrays(path, bands, tmp):
    """Each band as a float64 array, nodata as NaN (through gdal_translate to ENVI)."""
    out = []
    for b in bands:
        raw = pathlib.Path(tmp) / f"band{b}.bin"
        run(["gdal_translate", "-q", "-of", "ENVI", "-ot", "Float64", "-b", b, path, raw])
        info = json.loads(run(["gdalinfo", "-json", path]))
        w, h = info["size"]
        a = np.fromfile(raw, dtype="<f8").reshape(h, w)
        nodata = info["bands"][b - 1].get("noDataValue")
        if nodata is not None:
            a[a == nodata] = np.nan
        out.append(a)
    return out


def laplacian(a):
    """The 5-point discrete Laplacian (NaN on the border): the detail a plane misses."""
    out = np.full_like(a, np.nan)
    out[1:-1, 1:-1] = (a[:-2, 1:-1] + a[2:, 1:-1] + a[1:-1, :-2] + a[1:-1, 2:]
                       - 4 * a[1:-1, 1:-1])
    return out


def mean_correlation(arrays):
    """Mean Pearson correlation over every pair, on the samples valid in all."""
    if len(arrays) < 2:
        return 1.0
    valid = np.all([np.isfinite(a) for a in arrays], axis=0)
    flat = [a[valid] for a in arrays]
    c = np.corrcoef(flat)
    n = len(arrays)
    return float(c[np.triu_indices(n, 1)].mean())


def mesh(binary, src, bands, eps, tmp, tag):
    out = pathlib.Path(tmp) / f"{tag}.ply"
    rep = pathlib.Path(tmp) / f"{tag}.json"
    cmd = [binary, "mesh", src, "-o", out, "--max-error", eps, "--report", rep, "--quiet"]
    if len(bands) > 1:
        cmd += ["--bands", ",".join(map(str, bands))]
    else:
        cmd += ["--band", bands[0]]
    run(cmd)
    r = json.loads(rep.read_text())
    seconds = r["seconds"]["initial_mesh"] + r["seconds"]["decimate"]
    return r, out, seconds


def case(binary, label, src, bands, eps, singles, arrays, repeat, tmp):
    """One row: the joint mesh of `bands` against each band alone (cached in `singles`)."""
    for b in bands:
        if (b, eps) not in singles:
            r, _, _ = mesh(binary, src, [b], eps, tmp, f"single{b}")
            singles[(b, eps)] = r["triangles_after"]
    best_joint, best_single = float("inf"), float("inf")
    for _ in range(repeat):
        single, _, s = mesh(binary, src, [bands[0]], eps, tmp, "time1")
        best_single = min(best_single, s)
        r, out, s = mesh(binary, src, bands, eps, tmp, "joint")
        best_joint = min(best_joint, s)
    per_triangle = (best_joint / r["triangles_after"]) / (best_single / single["triangles_after"])
    if len(bands) > 1:
        run([binary, "verify", src, out, "--bands", ",".join(map(str, bands)),
             "--max-error", eps])
    before = r["triangles_before"]
    single_counts = [singles[(b, eps)] for b in bands]
    mean_single = sum(single_counts) / len(single_counts)
    corr = mean_correlation([arrays[b - 1] for b in bands])
    detail = mean_correlation([laplacian(arrays[b - 1]) for b in bands])
    worst = max(v["measured_max_error"] for v in r.get("variables", [])) if len(bands) > 1 else r["measured_max_error"]
    return (f"| {label} | {len(bands)} | {eps} | {corr:.3f} | {detail:.3f} | "
            f"{100 * (1 - mean_single / before):.1f} % | {100 * (1 - max(single_counts) / before):.1f} % | "
            f"{r['decimation_percent']:.1f} % | {r['triangles_after'] / mean_single:.2f} | "
            f"{worst:.4g} | {best_joint / best_single:.2f} | {per_triangle:.2f} |")


def codem_pair(data, tmp):
    """The CODEM pair on one grid: gdalwarp of the DEM onto the DSM's grid, then a
    two-band VRT; `None` and the reason when they share no valid sample."""
    dsm, dem = data / CODEM_DSM, data / CODEM_DEM
    info = json.loads(run(["gdalinfo", "-json", dsm]))
    w, h = info["size"]
    gt = info["geoTransform"]
    xmin, ymax = gt[0], gt[3]
    xmax, ymin = xmin + w * gt[1], ymax + h * gt[5]
    warped = pathlib.Path(tmp) / "dem_on_dsm.tif"
    run(["gdalwarp", "-q", "-overwrite", "-te", xmin, ymin, xmax, ymax, "-ts", w, h,
         "-r", "bilinear", "-dstnodata", "-9999", dem, warped])
    pair = pathlib.Path(tmp) / "codem_pair.vrt"
    run(["gdalbuildvrt", "-q", "-overwrite", "-separate", "-allow_projection_difference",
         pair, dsm, warped])
    both = bands_as_arrays(pair, [1, 2], tmp)
    common = int(np.sum(np.isfinite(both[0]) & np.isfinite(both[1])))
    if common < 4:
        return None, f"gdalwarp onto the DSM's grid leaves {common} samples valid in both"
    return pair, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    target = os.environ.get("CARGO_TARGET_DIR", "target")
    ap.add_argument("--bin", default=f"{target}/release/tinsmith")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out")
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    lines = [
        "| data | variables | ε | mean correlation | mean correlation of the Laplacians | "
        "mean single decimation | least single decimation | joint decimation | "
        "joint / mean single triangles | measured max error (worst variable) | "
        "time per sample vs one variable | time per output triangle vs one variable |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    notes = []
    with tempfile.TemporaryDirectory() as tmp:
        heart = data / HEART
        if not heart.exists():
            sys.exit(f"{heart}: missing; pass --shared DIR")
        arrays = bands_as_arrays(heart, list(range(1, 17)), tmp)
        singles = {}
        for eps in [4, 8, 16]:
            for n in [1, 2, 4, 8, 16]:
                lines.append(case(args.bin, "heart MR, frames 1..n", heart, list(range(1, n + 1)),
                                  eps, singles, arrays, args.repeat, tmp))
        pair, why = codem_pair(data, tmp)
        if pair is None:
            notes.append(f"CODEM pair: {why}: the AOI DSM is CODEM's deliberately rotated "
                         "and shifted copy, so as georeferenced the two do not overlap.")
            # Registered by pixel instead (the DSM given the DEM's georeferencing, both
            # cut to their common window): not the same ground, a low-correlation pair.
            dem = data / CODEM_DEM
            dsm_cut = pathlib.Path(tmp) / "dsm_cut.tif"
            run(["gdal_translate", "-q", "-srcwin", 0, 0, 405, 344, data / CODEM_DSM, dsm_cut])
            run(["gdal_edit.py", "-a_ullr", 626999.504176399, 4323885.918092704,
                 627404.504176399, 4323541.918092704, dsm_cut])
            pair = pathlib.Path(tmp) / "codem_pixels.vrt"
            run(["gdalbuildvrt", "-q", "-overwrite", "-separate", "-allow_projection_difference",
                 pair, dem, dsm_cut])
            label = "CODEM DEM + AOI DSM by pixel"
            notes.append("CODEM rows: the DEM and the AOI DSM's top-left 405 x 344 samples "
                         "stacked by pixel (gdalbuildvrt -separate), not registered.")
        else:
            label = "CODEM DSM + DEM"
        arrays = bands_as_arrays(pair, [1, 2], tmp)
        singles = {}
        for eps in [0.5, 1, 2]:
            for n in [1, 2]:
                lines.append(case(args.bin, label, pair, list(range(1, n + 1)), eps, singles,
                                  arrays, args.repeat, tmp))
    text = "\n".join(lines) + "\n" + "".join(f"\n{n}\n" for n in notes)
    print(text, end="")
    if args.out:
        pathlib.Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
