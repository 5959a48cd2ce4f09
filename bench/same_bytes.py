#!/usr/bin/env python3
"""Runs one tinsmith binary over a fixed set of cases and records the bytes it writes.

    python3 bench/same_bytes.py BINARY OUT.json [--shared ../shared] [--against OLD.json]

Every case runs the binary once; each output file (recursively, for tile directories)
is hashed with SHA-256, and stdout is hashed too (for `info` and `verify`). Report JSON
files are hashed without their wall-clock times (`seconds`, `*_seconds`), and in stdout and
JSON the checkout's, the shared data's and the work directory's paths are replaced by
placeholders, so runs from different checkouts compare. With `--against`, the
hashes are compared with an earlier run's and every difference is listed; the exit code
is 1 when any differs. Restructuring the code must leave every hash unchanged.
"""

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def cases(shared):
    """(name, args with {out} for the output directory) for every case."""
    sample = os.path.join(REPO, "data", "becmodel_dem_bc_albers_50m.tif")
    dems = [("sample", sample)]
    for name in [
        "topotoolbox_bigtujunga_30m.tif",
        "terra_elev_vinschgau.tif",
        "landlab_hugo_site.asc",
        "pysheds_dem_fortworth_3arcsec.tif",
        "tintn_valid_raster_3857.tif",
    ]:
        path = os.path.join(os.path.realpath(shared), "data", "dem", name)
        if os.path.exists(path):
            dems.append((name.split(".")[0], path))
    out = []
    for label, dem in dems:
        out.append((f"{label}-info", ["info", dem, "--json", "-q"]))
        for fmt in ["ply", "obj", "stl", "glb", "geojson", "fgb", "xml"]:
            out.append(
                (
                    f"{label}-mesh-{fmt}",
                    ["mesh", dem, "--max-error", "2.5", "-o", "{out}/m." + fmt, "-q",
                     "--report", "{out}/r.json"],
                )
            )
        out.append(
            (f"{label}-mesh-tiled", ["mesh", dem, "--max-error", "1", "--tile-size", "128",
                                     "-o", "{out}/t.ply", "-q", "--report", "{out}/r.json"])
        )
        out.append(
            (f"{label}-mesh-per-tile", ["mesh", dem, "--max-error", "1", "--tile-size", "128",
                                        "--per-tile", "{out}/pt", "-q"])
        )
        out.append(
            (f"{label}-mesh-count", ["mesh", dem, "--max-triangles", "3000", "-o",
                                     "{out}/c.obj", "-q"])
        )
        out.append(
            (f"{label}-mesh-base", ["mesh", dem, "--max-error", "4", "--base", "0",
                                    "-o", "{out}/b.stl", "-q"])
        )
        out.append(
            (f"{label}-mesh-zero", ["mesh", dem, "--max-error", "0", "-o", "{out}/z.ply", "-q"])
        )
        out.append(
            (f"{label}-verify", ["verify", dem, "{sample_mesh}", "--max-error", "2.5", "--json"])
        )
        out.append(
            (f"{label}-contour", ["contour", dem, "--interval", "25", "--max-error", "2",
                                  "-o", "{out}/c.fgb", "-q"])
        )
        out.append(
            (f"{label}-contour-grid", ["contour", dem, "--interval", "25", "--max-error", "0",
                                       "-o", "{out}/c.geojson", "-q"])
        )
        out.append(
            (f"{label}-tiles", ["tiles", dem, "-o", "{out}/tiles", "--max-zoom", "11",
                                "--metadata", "--normals", "-q", "--report", "{out}/r.json"])
        )
    return out


def digest(data):
    return hashlib.sha256(data).hexdigest()


def without_times(value):
    """A report without its wall-clock times (keys `seconds` and `*_seconds`)."""
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items()
                if k != "seconds" and not k.endswith("_seconds")}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


def without_paths(data, paths):
    """`data` with each of `paths` (placeholder -> path) replaced by its placeholder."""
    for placeholder, path in paths.items():
        data = data.replace(os.fsencode(path), placeholder.encode())
    return data


def hash_tree(root, paths):
    result = {}
    for dirpath, _, files in os.walk(root):
        for name in sorted(files):
            path = os.path.join(dirpath, name)
            rel = os.path.relpath(path, root)
            with open(path, "rb") as f:
                data = f.read()
            if name.endswith(".json"):
                data = without_paths(data, paths)
            if name.endswith(".json") and name.startswith("r"):
                try:
                    report = json.loads(data)
                    report = without_times(report)
                    data = json.dumps(report, sort_keys=True).encode()
                except ValueError:
                    pass
            result[rel] = digest(data)
    return result


def run(binary, shared):
    results = {}
    work = tempfile.mkdtemp(prefix="tinsmith-same-bytes-")
    # Longest first: the work directory may lie inside the checkout.
    paths = {"{work}": work, "{shared}": os.path.realpath(shared), "{repo}": REPO}
    paths = dict(sorted(paths.items(), key=lambda kv: -len(kv[1])))
    try:
        for name, args in cases(shared):
            out = os.path.join(work, name)
            os.makedirs(out)
            mesh_for_verify = os.path.join(work, name.rsplit("-", 1)[0] + "-mesh-ply", "m.ply")
            argv = [a.replace("{out}", out).replace("{sample_mesh}", mesh_for_verify)
                    for a in args]
            proc = subprocess.run([binary] + argv, capture_output=True)
            stdout = without_paths(proc.stdout, paths)
            entry = {"exit": proc.returncode, "stdout": digest(stdout)}
            entry["files"] = hash_tree(out, paths)
            results[name] = entry
            status = "ok" if proc.returncode == 0 else f"exit {proc.returncode}"
            print(f"{name}: {status}, {len(entry['files'])} file(s)", file=sys.stderr)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("out")
    parser.add_argument("--shared", default=os.path.join(REPO, "..", "shared"))
    parser.add_argument("--against")
    args = parser.parse_args()
    results = run(os.path.abspath(args.binary), args.shared)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1, sort_keys=True)
    if not args.against:
        return 0
    with open(args.against) as f:
        old = json.load(f)
    differ = 0
    for name in sorted(set(old) | set(results)):
        if old.get(name) != results.get(name):
            differ += 1
            print(f"DIFFERS: {name}\n  before: {old.get(name)}\n  now:    {results.get(name)}")
    total = len(set(old) | set(results))
    print(f"{total - differ} of {total} cases byte-identical")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
