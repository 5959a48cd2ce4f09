"""Rewrites a LAS/LAZ file as COPC (cloud-optimized point cloud: LAZ 1.4 whose points sit
in an octree of variable-size chunks) with copclib, a writer independent of tinsmith's
reader. Points are spread over the octree's first DEPTH levels (each node a chunk of its
own size), so a reader must follow the COPC chunk table; class, withheld flag and the
WKT CRS are carried over. Prints the number of nodes written.

Usage: python3 tests/oracles/copc_write.py IN.las OUT.copc.laz [DEPTH]
"""
import sys

import copclib as copc
import laspy
import numpy as np


def main():
    source, destination = sys.argv[1], sys.argv[2]
    depth = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    las = laspy.read(source)
    x, y, z = (np.asarray(c, dtype=float) for c in (las.x, las.y, las.z))
    classes = np.asarray(las.classification)
    withheld = np.asarray(las.withheld, dtype=bool)
    # The WKT record's own text, carried as it is.
    wkt = next(
        (v.string for v in las.header.vlrs if isinstance(v, laspy.vlrs.known.WktCoordinateSystemVlr)),
        "",
    )
    low = np.array([x.min(), y.min(), z.min()])
    span = max(x.max() - low[0], y.max() - low[1], z.max() - low[2]) * 1.001 + 1e-3
    scale = tuple(float(s) for s in las.header.scales)
    config = copc.CopcConfigWriter(
        6, scale, tuple(float(o) for o in las.header.offsets), wkt
    )
    config.las_header.min = copc.Vector3(*low)
    config.las_header.max = copc.Vector3(*(low + span))
    config.copc_info.spacing = span / 64
    writer = copc.FileWriter(destination, config)
    header = writer.copc_config.las_header
    # Each point to a level chosen by its index, and to that level's voxel holding it.
    nodes = {}
    for i in range(len(x)):
        level = i % (depth + 1)
        n = 2**level
        key = (level,) + tuple(
            min(int((v - lo) / span * n), n - 1) for v, lo in zip((x[i], y[i], z[i]), low)
        )
        nodes.setdefault(key, []).append(i)
    for key in sorted(nodes):
        points = copc.Points(header)
        for i in nodes[key]:
            p = points.CreatePoint()
            p.x, p.y, p.z = float(x[i]), float(y[i]), float(z[i])
            p.classification = int(classes[i])
            p.withheld = bool(withheld[i])
            p.return_number, p.number_of_returns = 1, 1
            points.AddPoint(p)
        writer.AddNode(copc.VoxelKey(*key), points)
    writer.Close()
    print(len(nodes))


if __name__ == "__main__":
    main()
