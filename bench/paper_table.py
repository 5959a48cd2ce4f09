#!/usr/bin/env python3
"""Reproduce the paper's decimation table (Schikore & Bajaj 1995, section 4) with tinsmith.

Runs `tinsmith mesh --error-model bounds` on the comparable slices in ../shared/data/scalar,
verifies every written mesh with `tinsmith verify`, and prints a Markdown table with the
paper's percentages beside ours. Usage (from the repository root, after
`cargo build --release`):

    python3 bench/paper_table.py [--shared ../shared] [--out docs/paper-table.md]
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

CASES = [
    # (label, file, [(epsilon, paper percentage)])
    ("heart MR, 8-bit 256x256 (frame 7)", "scalar/mr_heart_256x256_u8_frame07.png",
     [(2, 41), (4, 60), (8, 73), (16, 82)]),
    ("head CT, 16-bit 512x512 (matplotlib ct.raw)", "scalar/mpl_ct_head_512x512_u16.png",
     [(2, 48), (20, 56), (100, 70), (200, 78), (500, 86), (1000, 90)]),
    ("head CT, 16-bit 512x512 (Barre CT-MONO2-16-brain)", "scalar/ct_brain_512x512_i16.tif",
     [(2, 48), (20, 56), (100, 70), (200, 78), (500, 86), (1000, 90)]),
]


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shared", default="../shared")
    ap.add_argument("--bin", default="target/release/tinsmith")
    ap.add_argument("--selection", default="hybrid")
    ap.add_argument("--out")
    args = ap.parse_args()
    data = pathlib.Path(args.shared) / "data"
    lines = [
        f"| data | ε | paper decimation | tinsmith decimation | triangles before → after | measured max error | verified | seconds |",
        "|---|---|---|---|---|---|---|---|",
    ]
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for label, rel, rows in CASES:
            src = data / rel
            if not src.exists():
                sys.exit(f"{src}: missing; pass --shared DIR")
            for eps, paper in rows:
                out = pathlib.Path(tmp) / "m.ply"
                rep = pathlib.Path(tmp) / "r.json"
                code, _, err = run([args.bin, "mesh", str(src), "-o", str(out), "--max-error", str(eps),
                                    "--error-model", "bounds", "--selection", args.selection,
                                    "--initial-mesh", "full", "--order", "sweep", "--retriangulate", "ears",
                                    "--report", str(rep)])
                if code != 0:
                    sys.exit(f"mesh failed on {src} at {eps}: {err}")
                r = json.loads(rep.read_text())
                code, vout, _ = run([args.bin, "verify", str(src), str(out), "--max-error", str(eps), "--json"])
                v = json.loads(vout)
                passed = code == 0 and v["max_error"] <= eps
                ok &= passed
                lines.append(
                    f"| {label} | {eps} | {paper} % | {r['decimation_percent']:.1f} % | "
                    f"{r['triangles_before']} → {r['triangles_after']} | {v['max_error']:.4g} | "
                    f"{'yes' if passed else 'NO'} | {r['seconds']['total']:.2f} |")
    table = "\n".join(lines) + "\n"
    print(table, end="")
    if args.out:
        pathlib.Path(args.out).write_text(table)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
