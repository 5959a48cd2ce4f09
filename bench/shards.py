#!/usr/bin/env python3
"""Benchmark of sharded pyramids (docs/results.md, "Sharded pyramids"). Not a test.

  etopo5  ETOPO5 (4320 x 2161, 0..360) at its own level: one process (`tinsmith tiles
          --threads 2`) against 4 shards on a Dask LocalCluster of 2 worker processes
          (tools/dask_tiles.py, each shard --threads 1) and the merge (--threads 2), in
          the same invocation, --repeat times (medians): the sharded run's CPU (shards +
          merge) over the one process's, wall times, peak RSS per shard, and whether the
          two pyramids are the same bytes (every file but tinsmith/, the records).
  16k     the same for a 16384 x 8192 bilinear resample of ETOPO5 (gdalwarp, Float32, in
          --work), --repeat-16k times.
  planet  planning at planet scale without the data: VRTs of 432000 x 216000 samples (3
          arc-seconds) that read ETOPO5 upsampled, one whole (as a global DEM with
          bathymetry) and one with the sea (heights below 0) as nodata (as a land DEM):
          shard 0 of 1000 of each is run to the end with --threads 2; its own log line
          "planned in" gives the plan time (the whole plan: open, bounds, the coarse read
          that weighs the blocks, the weights), its record the plan's weights, from which
          the 1000 shards' weights are recomputed (the midpoint rule of plan.rs) for the
          balance. The shard's cost is a measured planet-scale shard.

Then the projection of the planet pyramid on 100 machines of 2 cores, from the ETOPO5
throughput (lattice samples of its own level per CPU-second of the sharded run), with the
arithmetic. Prints Markdown (also to --out).

Usage (from the repository root, after `make deps`; GDAL's command-line tools):
    cargo build --release
    .venv/bin/python bench/shards.py [--shared ../shared] [--work /tmp/tinsmith-shards]
        [--sections etopo5,16k,planet] [--repeat 3] [--repeat-16k 1] [--out FILE.md]

Each run is measured on its own process (os.wait4): wall, user + system CPU, peak RSS.
The machine may be shared: the load average before each section is printed.
"""
import argparse
import hashlib
import importlib.util
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARDS = 4
WORKERS = 2
PLANET_SHARDS = 1000
PLANET_SIZE = (432000, 216000)


def load_driver():
    """tools/dask_tiles.py as a module (its run_measured measures one child)."""
    spec = importlib.util.spec_from_file_location("dask_tiles", ROOT / "tools/dask_tiles.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


DRIVER = load_driver()


def measured(cmd):
    """Runs `cmd`, exiting on failure; its costs (DRIVER.run_measured) and whole stderr."""
    r = DRIVER.run_measured([str(c) for c in cmd], tail=1 << 30)
    if r["exit"] != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{r['stderr_tail']}")
    return r


def sh(cmd):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return p.stdout


def load():
    return os.getloadavg()[0]


def pyramid_hashes(root):
    """SHA-256 of every file under root but tinsmith/ (the records), by relative path."""
    out = {}
    for path in sorted(pathlib.Path(root).rglob("*")):
        rel = path.relative_to(root)
        if rel.parts[0] == "tinsmith" or not path.is_file():
            continue
        out[str(rel)] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def own_level_samples(work):
    """Lattice samples of the input's own level: the tiles `tinsmith tiles` writes there
    (from the one-process --report) times their lattice's cells squared."""
    report = json.loads((work / "one-report.json").read_text())
    finest = report["levels"][-1]
    return finest["level"], finest["tiles"] * report["lattice_cells"] ** 2


def reach_overhead(split, anchor, cells):
    """Lattice samples a global pyramid's blocks sample at the anchor level (each block's
    tiles and the band of 3 x 2^(anchor - split) - 2 samples around them that its tiles and
    filters read, clipped at the poles, as blocks.rs's block_level), over the level's own."""
    f = anchor - split
    margin = 3 * (1 << f) - 2
    side = (1 << f) * cells
    columns, rows = (2 << anchor) * cells, (1 << anchor) * cells
    width = min(side + 2 * margin, columns)
    heights = [min((y + 1) * side + margin, rows) - max(y * side - margin, 0)
               for y in range(1 << split)]
    return width * sum(heights) * (2 << split) / (columns * rows)


def compare(args, label, path, repeat, single_thread=False):
    """One process against SHARDS shards on WORKERS Dask workers, `repeat` times (and
    the one process on one thread too, with `single_thread`)."""
    work = args.work / label
    work.mkdir(parents=True, exist_ok=True)
    runs = []
    identical = []
    print(f"{label}: load {load():.2f} before", file=sys.stderr)
    for k in range(repeat):
        one, sharded = work / "one", work / "sharded"
        shutil.rmtree(one, ignore_errors=True)
        shutil.rmtree(sharded, ignore_errors=True)
        single = measured([args.tinsmith, "tiles", path, "-o", one, "--threads", "2", "-q",
                           "--report", work / "one-report.json"])
        if single_thread:
            shutil.rmtree(one, ignore_errors=True)
            single["threads_1"] = measured([args.tinsmith, "tiles", path, "-o", one,
                                            "--threads", "1", "-q"])
            shutil.rmtree(one, ignore_errors=True)
            measured([args.tinsmith, "tiles", path, "-o", one, "--threads", "2", "-q"])
        start = time.monotonic()
        summary_path = work / "summary.json"
        p = subprocess.run([args.python, ROOT / "tools/dask_tiles.py", path, "-o", sharded,
                            "--shards", str(SHARDS), "--workers", str(WORKERS),
                            "--tinsmith", args.tinsmith, "--shard-threads", "1",
                            "--merge-threads", "2", "--summary", summary_path],
                           capture_output=True, text=True)
        driver_wall = time.monotonic() - start
        if p.returncode != 0:
            sys.exit(f"the driver failed:\n{p.stderr}")
        summary = json.loads(summary_path.read_text())
        identical.append(pyramid_hashes(one) == pyramid_hashes(sharded))
        runs.append({"one": single, "summary": summary, "driver_wall": driver_wall})
        t = summary["totals"]
        print(f"  run {k + 1}: one {single['wall_s']:.1f} s wall {single['cpu_s']:.1f} s CPU; "
              f"sharded {driver_wall:.1f} s wall {t['cpu_s']:.1f} s CPU; "
              f"identical {identical[-1]}", file=sys.stderr)
    level, samples = own_level_samples(work)
    tiles = len([k for k in pyramid_hashes(work / "one") if k.endswith(".terrain")])
    plan = json.loads((work / "sharded/tinsmith/shards" / f"0-of-{SHARDS}.json").read_text())["plan"]
    return {"label": label, "runs": runs, "identical": identical, "level": level,
            "samples": samples, "tiles": tiles, "plan": plan}


def med(values):
    return statistics.median(values)


def compare_markdown(c):
    runs = c["runs"]
    one_cpu = [r["one"]["cpu_s"] for r in runs]
    one_wall = [r["one"]["wall_s"] for r in runs]
    sh_cpu = [r["summary"]["totals"]["cpu_s"] for r in runs]
    ratio = [s / o for s, o in zip(sh_cpu, one_cpu)]
    lines = [
        f"**{c['label']}**: {c['tiles']} tiles, own level {c['level']} "
        f"({c['samples'] / 1e6:.1f} M lattice samples); {len(runs)} run(s), medians; "
        f"byte-identical (all files but tinsmith/): "
        f"{'yes' if all(c['identical']) else 'NO'} ({sum(c['identical'])} of {len(runs)})",
        "",
        "| run | wall s | CPU s | peak RSS MB |",
        "|---|---|---|---|",
        f"| one process, --threads 2 | {med(one_wall):.1f} | {med(one_cpu):.1f} | "
        f"{med([r['one']['max_rss_mb'] for r in runs]):.0f} |",
        f"| {SHARDS} shards + merge on {WORKERS} Dask workers (driver, cluster start "
        f"included) | {med([r['driver_wall'] for r in runs]):.1f} | {med(sh_cpu):.1f} | "
        f"{med([r['summary']['totals']['max_shard_rss_mb'] for r in runs]):.0f} (largest "
        f"shard) |",
    ]
    # The run whose CPU ratio is the median, shard by shard.
    mid = sorted(range(len(runs)), key=lambda i: ratio[i])[len(runs) // 2]
    s = runs[mid]["summary"]
    for r in s["results"]:
        lines.append(f"| shard {r['shard']} ({r['blocks']} blocks, "
                     f"{100 * r['weight'] / r['total_weight']:.1f} % of the weight) | "
                     f"{r['wall_s']:.1f} | {r['cpu_s']:.1f} | {r['max_rss_mb']:.0f} |")
    m = s["merge"]
    lines.append(f"| merge, --threads 2 | {m['wall_s']:.1f} | {m['cpu_s']:.1f} | "
                 f"{m['max_rss_mb']:.0f} |")
    if "threads_1" in runs[0]["one"]:
        t1 = [r["one"]["threads_1"] for r in runs]
        lines.append(f"| one process, --threads 1 | {med([t['wall_s'] for t in t1]):.1f} | "
                     f"{med([t['cpu_s'] for t in t1]):.1f} | "
                     f"{med([t['max_rss_mb'] for t in t1]):.0f} |")
    plan = c["plan"]
    global_ = plan["bounds"][:4] == [-180.0, -90.0, 180.0, 90.0]
    if global_:
        one_split = max(plan["anchor"] - 4, 0)
        cells = plan["options"].get("cells", 217)
        rings = (reach_overhead(one_split, plan["anchor"], cells),
                 reach_overhead(plan["split"], plan["anchor"], cells))
        ring_text = (f" Each block samples its tiles and a band around them: at the anchor "
                     f"level {plan['anchor']} the one process (blocks at level {one_split}) "
                     f"samples {rings[0]:.3f} x the level's samples, the {SHARDS} shards "
                     f"(blocks at level {plan['split']}, for at least 8 per shard) "
                     f"{rings[1]:.3f} x.")
    else:
        ring_text = ""
    lines += [
        "",
        f"CPU of the sharded run / one process: **{med(ratio):.3f}** "
        f"(runs: {', '.join(f'{x:.3f}' for x in ratio)}; target <= 1.10). "
        f"Throughput of the sharded run: "
        f"{c['samples'] / med(sh_cpu) / 1e6:.2f} M samples per CPU-second "
        f"(one process: {c['samples'] / med(one_cpu) / 1e6:.2f} M).{ring_text}",
        "",
    ]
    return "\n".join(lines), c["samples"] / med(sh_cpu)


def planet_vrts(args):
    """Two VRTs of PLANET_SIZE reading ETOPO5: whole, and with the sea as nodata."""
    work = args.work / "planet"
    work.mkdir(parents=True, exist_ok=True)
    etopo = args.shared / "data/dem/etopo5_global_5arcmin.tif"
    whole = work / "planet.vrt"
    sh(["gdal_translate", "-q", "-of", "VRT", "-outsize", *map(str, PLANET_SIZE), etopo, whole])
    text = whole.read_text()
    # Heights below 0 (the sea) to -32768, the band's nodata: a land DEM.
    land_text = text.replace("<SimpleSource>", "<ComplexSource>").replace(
        "</SimpleSource>",
        "<LUT>-20000:-32768,-0.5:-32768,0:0,20000:20000</LUT></ComplexSource>")
    land_text = land_text.replace(
        "<VRTRasterBand dataType=\"Int16\" band=\"1\">",
        "<VRTRasterBand dataType=\"Int16\" band=\"1\"><NoDataValue>-32768</NoDataValue>")
    if "<LUT>" not in land_text or "<NoDataValue>" not in land_text:
        sys.exit(f"unexpected VRT from gdal_translate:\n{text}")
    land = work / "planet_land.vrt"
    land.write_text(land_text)
    return [("planet, whole (bathymetry)", whole), ("planet, land only", land)]


def shard_blocks(weights, shards):
    """plan.rs's midpoint rule: block k goes to the shard whose share of the total
    weight holds the middle of the block's weight. Returns each shard's weight, blocks."""
    total = sum(weights)
    per = [[0, 0] for _ in range(shards)]
    before = 0
    for w in weights:
        middle = 2 * before + w
        before += w
        owner = min(middle * shards // (2 * total), shards - 1)
        per[owner][0] += w
        per[owner][1] += 1
    return per


def planet(args):
    out = []
    for label, vrt in planet_vrts(args):
        dest = args.work / "planet" / (vrt.stem + "-out")
        shutil.rmtree(dest, ignore_errors=True)
        print(f"{label}: load {load():.2f} before", file=sys.stderr)
        cmd = [args.tinsmith, "tiles", vrt, "-o", dest, "--shard", f"0/{PLANET_SHARDS}",
               "--threads", "2", "--report", args.work / "planet" / f"{vrt.stem}-report.json"]
        r = measured(cmd)
        planned = [line for line in r["stderr_tail"].splitlines() if "planned in" in line]
        record = json.loads((dest / f"tinsmith/shards/0-of-{PLANET_SHARDS}.json").read_text())
        plan = record["plan"]
        weights = plan["weights"]
        per = shard_blocks(weights, PLANET_SHARDS)
        if per[0][1] != len(record["blocks"]):
            sys.exit(f"the recomputed partition gives shard 0 {per[0][1]} blocks, the "
                     f"record {len(record['blocks'])}")
        mean = sum(weights) / PLANET_SHARDS
        w = [p[0] for p in per]
        blocks = [p[1] for p in per]
        report = json.loads((args.work / "planet" / f"{vrt.stem}-report.json").read_text())
        out.append({"label": label, "vrt": vrt, "run": r, "planned": planned,
                    "split": plan["split"], "anchor": plan["anchor"], "blocks": len(weights),
                    "max_mean": max(w) / mean, "min_mean": min(w) / mean,
                    "blocks_range": (min(blocks), max(blocks)),
                    "empty_shards": sum(1 for b in blocks if b == 0),
                    "shard0": report, "total_weight": sum(weights)})
        print(f"  {planned}; shard 0: {r['wall_s']:.1f} s wall {r['cpu_s']:.1f} s CPU "
              f"{r['max_rss_mb']:.0f} MB", file=sys.stderr)
    return out


def planet_markdown(results, throughput):
    lines = [
        f"**Planet, {PLANET_SIZE[0]} x {PLANET_SIZE[1]} samples (VRTs upsampling ETOPO5), "
        f"{PLANET_SHARDS} shards**: shard 0 run to the end, --threads 2.",
        "",
        "| input | plan (shard's log) | blocks (split level) | shard weights max/mean | "
        "min/mean | blocks per shard | shard 0: wall s, CPU s, peak MB, tiles |",
        "|---|---|---|---|---|---|---|",
    ]
    for p in results:
        r = p["run"]
        plan = p["planned"][0].split("planned in ")[1].split(":")[0] if p["planned"] else "?"
        s0 = p["shard0"]
        lines.append(
            f"| {p['label']} | {plan} | {p['blocks']} (level {p['split']}; anchor "
            f"{p['anchor']}) | {p['max_mean']:.3f} | {p['min_mean']:.3f} | "
            f"{p['blocks_range'][0]}–{p['blocks_range'][1]} | {r['wall_s']:.1f}, "
            f"{r['cpu_s']:.1f}, {r['max_rss_mb']:.0f}, {s0['tiles']} |")
    lines.append("")
    for p in results:
        lines.append(f"- {p['label']}: `{p['planned'][0].strip() if p['planned'] else ''}`")
    lines.append("")
    if throughput:
        anchor = results[0]["anchor"]
        tiles = (2 << anchor) * (1 << anchor)
        cells = results[0]["shard0"]["lattice_cells"]
        samples = tiles * cells ** 2
        cpu = samples / throughput
        cores = 200
        lines += [
            "**Projection**, 100 machines of 2 cores (200 shards at a time):",
            "",
            f"- the planet's own level {anchor}: 2^{anchor + 1} x 2^{anchor} = {tiles:,} tiles "
            f"x {cells}^2 = {samples / 1e9:.1f} G lattice samples (every tile: a global DEM);",
            f"- at ETOPO5's sharded throughput, {throughput / 1e6:.2f} M samples per "
            f"CPU-second: {samples / 1e9:.1f} G / {throughput / 1e6:.2f} M = {cpu:,.0f} "
            f"CPU-seconds ({cpu / 3600:,.0f} CPU-hours);",
            f"- on {cores} cores: {cpu:,.0f} / {cores} = {cpu / cores:,.0f} s = "
            f"{cpu / cores / 3600:.1f} h if the work divided evenly. Dask hands each free "
            f"core the next of the {PLANET_SHARDS} shards, so the last core finishes at most "
            f"one shard after the mean (list scheduling): the largest shard is "
            f"{results[0]['max_mean']:.2f} x the mean shard, {cpu / PLANET_SHARDS:,.0f} "
            f"CPU-s, so the shards end within {cpu / cores:,.0f} + "
            f"{results[0]['max_mean'] * cpu / PLANET_SHARDS:,.0f} = "
            f"{(cpu / cores + results[0]['max_mean'] * cpu / PLANET_SHARDS) / 3600:.1f} h; "
            f"each core also plans {PLANET_SHARDS // cores} times "
            f"(the plan's time above each);",
            "- then the merge, on one machine: levels 0 to "
            f"{results[0]['split'] - 1} from the {results[0]['blocks']:,} blocks' samples "
            "(not measured here);",
        ]
        r = results[0]["run"]
        s0 = results[0]["shard0"]
        s0_samples = s0["levels"][-1]["tiles"] * s0["lattice_cells"] ** 2
        s0_rate = s0_samples / r["cpu_s"]
        lines.append(
            f"- the measured planet shard 0 ({s0_samples / 1e6:.0f} M samples at level "
            f"{anchor}, {r['cpu_s']:.1f} CPU-s: {s0_rate / 1e6:.2f} M samples per "
            f"CPU-second; the VRT's nearest-neighbour upsampling makes flat 100 x 100 "
            f"plateaus, easier than real terrain) would give {samples / s0_rate:,.0f} "
            f"CPU-s, {samples / s0_rate / cores:,.0f} s on {cores} cores.")
        lines.append("")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--shared", type=pathlib.Path, default=ROOT.parent / "shared")
    p.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/tinsmith-shards"))
    p.add_argument("--tinsmith", type=pathlib.Path, default=ROOT / "target/release/tinsmith")
    p.add_argument("--python", type=pathlib.Path, default=ROOT / ".venv/bin/python")
    p.add_argument("--sections", default="etopo5,16k,planet")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--repeat-16k", type=int, default=1)
    p.add_argument("--out", type=pathlib.Path)
    args = p.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    args.tinsmith = args.tinsmith.resolve()
    sections = args.sections.split(",")
    etopo = args.shared / "data/dem/etopo5_global_5arcmin.tif"
    md = ["## Sharded pyramids (bench/shards.py)", ""]
    throughput = None
    if "etopo5" in sections:
        text, throughput = compare_markdown(
            compare(args, "ETOPO5", etopo, args.repeat, single_thread=True))
        md.append(text)
    if "16k" in sections:
        big = args.work / "etopo5_16384x8192.tif"
        if not big.exists():
            sh(["gdalwarp", "-q", "-ts", "16384", "8192", "-r", "bilinear", "-ot", "Float32",
                "-co", "TILED=YES", etopo, big])
        text, _ = compare_markdown(compare(args, "ETOPO5 16384 x 8192", big, args.repeat_16k))
        md.append(text)
    if "planet" in sections:
        md.append(planet_markdown(planet(args), throughput))
    text = "\n".join(md)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
