"""Reads a mesh file with trimesh (an independent reader from PyPI, installed by
`make deps` into .venv) and prints what it found as JSON on stdout.

Usage: .venv/bin/python3 tests/oracles/mesh_read.py FILE

Output: {"vertices": [[x, y, z], ...], "faces": [[a, b, c], ...],
         "watertight": bool, "winding_consistent": bool, "volume": float}
GLB scenes are flattened with their node transforms and mapped from glTF's Y-up axes back
to world axes (x, -z, y). trimesh merges STL corners into shared vertices by position.
"""
import json
import sys

import numpy as np
import trimesh


def main():
    path = sys.argv[1]
    loaded = trimesh.load(path, process=False)
    if isinstance(loaded, trimesh.Scene):
        mesh = loaded.to_mesh()
        # glTF (x, y, z) = world (x, z, -y): back to world axes.
        v = np.asarray(mesh.vertices, dtype=np.float64)
        mesh = trimesh.Trimesh(vertices=np.column_stack([v[:, 0], -v[:, 2], v[:, 1]]),
                               faces=mesh.faces, process=False)
    else:
        mesh = loaded
    if path.lower().endswith(".stl"):
        mesh.merge_vertices(digits_vertex=None)
    out = {
        "vertices": np.asarray(mesh.vertices, dtype=np.float64).tolist(),
        "faces": np.asarray(mesh.faces, dtype=np.int64).tolist(),
        "watertight": bool(mesh.is_watertight),
        "winding_consistent": bool(mesh.is_winding_consistent),
        "volume": float(mesh.volume) if mesh.is_watertight else None,
    }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
