"""Reads a PLY file with trimesh (an independent reader from PyPI, installed by
`make deps` into .venv) and prints its vertex properties as JSON on stdout.

Usage: .venv/bin/python3 tests/oracles/ply_properties.py FILE.ply

Output: {"names": ["x", "y", "z", ...], "columns": {"name": [values...]},
         "faces": [[a, b, c], ...]}
"""
import json
import sys

import numpy as np
import trimesh


def main():
    mesh = trimesh.load(sys.argv[1], process=False)
    data = mesh.metadata["_ply_raw"]["vertex"]["data"]
    names = list(data.dtype.names)
    out = {
        "names": names,
        "columns": {n: np.asarray(data[n], dtype=np.float64).ravel().tolist() for n in names},
        "faces": np.asarray(mesh.faces, dtype=np.int64).tolist(),
    }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
