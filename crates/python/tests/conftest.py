"""Fixtures of the package's tests: the sample DEM as numpy (no GDAL), the CLI binary, and
an independent check of the bound written here in numpy (no tinsmith code)."""

import json
import os
import pathlib

import numpy as np
import pytest

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[2]


@pytest.fixture(scope="session")
def becmodel():
    """data/becmodel_dem_bc_albers_50m.tif as an int16 array, with its geotransform and
    nodata value (tests/data/make_fixtures.sh made them with GDAL)."""
    a = np.load(HERE / "data" / "becmodel.npy")
    meta = json.loads((HERE / "data" / "becmodel.json").read_text())
    return a, tuple(meta["transform"]), meta["nodata"]


@pytest.fixture(scope="session")
def cli():
    """The `tinsmith` binary built from this tree (`make python-test` builds it)."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    path = pathlib.Path(os.environ.get("TINSMITH_CLI", target / "release" / "tinsmith"))
    if not path.is_file():
        pytest.fail(f"{path} is missing: build it with cargo build --release (make python-test does)")
    return path


def max_error_numpy(heights, vertices, triangles):
    """The largest |sample - TIN| over the samples the TIN covers, and the number of valid
    samples it covers, computed independently: every triangle (vertices in (column, row,
    value) coordinates) scan-converted over its bounding box with barycentric coordinates
    in float64, each covered sample interpolated linearly. Samples on shared edges are
    measured by each triangle; NaN samples covered count as an error (returned as inf)."""
    v = np.asarray(vertices, dtype=np.float64)
    worst, covered = 0.0, np.zeros(heights.shape, dtype=bool)
    for a, b, c in np.asarray(triangles, dtype=np.int64):
        (xa, ya, za), (xb, yb, zb), (xc, yc, zc) = v[a], v[b], v[c]
        x0, x1 = int(min(xa, xb, xc)), int(max(xa, xb, xc))
        y0, y1 = int(min(ya, yb, yc)), int(max(ya, yb, yc))
        ys, xs = np.mgrid[y0 : y1 + 1, x0 : x1 + 1]
        det = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
        if det == 0:
            return np.inf, 0
        l1 = ((xs - xa) * (yc - ya) - (xc - xa) * (ys - ya)) / det
        l2 = ((xb - xa) * (ys - ya) - (xs - xa) * (yb - ya)) / det
        l0 = 1.0 - l1 - l2
        eps = 1e-12
        inside = (l0 >= -eps) & (l1 >= -eps) & (l2 >= -eps)
        if not inside.any():
            continue
        z = l0 * za + l1 * zb + l2 * zc
        sample = heights[ys[inside], xs[inside]].astype(np.float64)
        if np.isnan(sample).any():
            return np.inf, 0
        worst = max(worst, float(np.abs(sample - z[inside]).max()))
        covered[ys[inside], xs[inside]] = True
    return worst, int(covered.sum())


def domain_samples(valid):
    """Samples that are a corner of a cell with four valid corners (what a TIN covers)."""
    cell = valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]
    d = np.zeros_like(valid)
    d[:-1, :-1] |= cell
    d[1:, :-1] |= cell
    d[:-1, 1:] |= cell
    d[1:, 1:] |= cell
    return int(d.sum())
