"""Reads a mesh file with trimesh (an independent reader from PyPI, installed by
`make deps` into .venv) and prints its vertices and vertex colours as JSON on stdout.

Usage: .venv/bin/python3 tests/oracles/vertex_colours.py FILE

Output: {"vertices": [[x, y, z], ...], "colours": [[r, g, b], ...]} (0..255)
GLB scenes are flattened with their node transforms and mapped from glTF's Y-up axes back
to world axes (x, -z, y).
"""
import json
import sys

import numpy as np
import trimesh


def main():
    loaded = trimesh.load(sys.argv[1], process=False)
    if isinstance(loaded, trimesh.Scene):
        mesh = loaded.to_mesh()
        v = np.asarray(mesh.vertices, dtype=np.float64)
        vertices = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])
    else:
        mesh = loaded
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
    colours = np.asarray(mesh.visual.vertex_colors)[:, :3]
    json.dump({"vertices": vertices.tolist(), "colours": colours.astype(int).tolist()},
              sys.stdout)


if __name__ == "__main__":
    main()
