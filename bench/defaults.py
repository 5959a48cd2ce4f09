#!/usr/bin/env python3
"""Measure option combinations of `tinsmith mesh` to pick the defaults.

For each DEM and epsilon, runs each configuration (best of --repeat runs), and prints
triangles and decimation seconds (initial mesh + decimation, from --report) per
configuration, as a Markdown table. Usage, from the repository root after
`cargo build --release`:

    python3 bench/defaults.py [--shared ../shared] [--eps 0.5,1,5,30] [--repeat 2]
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

DEMS = {
    "bigtujunga": "dem/topotoolbox_bigtujunga_30m.tif",
    "becmodel": "dem/becmodel_dem_bc_albers_50m.tif",
    "vinschgau": "dem/terra_elev_vinschgau.tif",
    "ct_head": "scalar/mpl_ct_head_512x512_u16.png",
}

CONFIGS = {
    "paper (bounds, full, sweep, ears hybrid)": "--error-model bounds --initial-mesh full --order sweep --retriangulate ears --selection hybrid",
    "exact, full, sweep, ears hybrid": "--error-model exact --initial-mesh full --order sweep --retriangulate ears --selection hybrid",
    "exact, rtin, sweep, ears hybrid": "--error-model exact --initial-mesh rtin --order sweep --retriangulate ears --selection hybrid",
    "exact, rtin, sweep, ears min-introduced": "--error-model exact --initial-mesh rtin --order sweep --retriangulate ears --selection min-introduced",
    "exact, rtin, sweep, dp": "--error-model exact --initial-mesh rtin --order sweep --retriangulate dp",
    "exact, rtin, greedy, ears hybrid": "--error-model exact --initial-mesh rtin --order greedy --retriangulate ears --selection hybrid",
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bin", default="target/release/tinsmith")
    ap.add_argument("--eps", default="0.5,1,5,30")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--dems", default=",".join(DEMS))
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    names = list(CONFIGS)
    print("| DEM | ε | " + " | ".join(names) + " |")
    print("|---|---|" + "---|" * len(names))
    with tempfile.TemporaryDirectory() as tmp:
        for dem in args.dems.split(","):
            for eps in args.eps.split(","):
                cells = []
                for name in names:
                    best = None
                    for _ in range(args.repeat):
                        rep = pathlib.Path(tmp) / "r.json"
                        cmd = [args.bin, "mesh", str(data / DEMS[dem]), "-o", f"{tmp}/m.ply", "-q",
                               "--max-error", eps, "--report", str(rep)] + CONFIGS[name].split()
                        p = subprocess.run(cmd, capture_output=True, text=True)
                        if p.returncode != 0:
                            sys.exit(p.stderr)
                        r = json.loads(rep.read_text())
                        s = r["seconds"]["initial_mesh"] + r["seconds"]["decimate"]
                        best = s if best is None else min(best, s)
                    cells.append(f"{r['triangles_after']} / {best:.2f} s")
                print(f"| {dem} | {eps} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
