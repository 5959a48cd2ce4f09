"""The README's Python examples, run as written on the bundled sample DEM, with rasterio
and rioxarray reading it (GDAL in their own wheels) and the bound checked in numpy."""

import os
import re

import numpy as np
import rasterio
import trimesh

from conftest import REPO, max_error_numpy

DEM = REPO / "data" / "becmodel_dem_bc_albers_50m.tif"


def readme_block(after):
    """The first ```python block of README.md after the line starting with `after`."""
    text = (REPO / "README.md").read_text()
    start = text.index("\n" + after)
    match = re.search(r"```python\n(.*?)```", text[start:], re.S)
    assert match, f"no python block after {after!r}"
    return match.group(1)


def run_example(block, tmp_path):
    """Runs `block` in `tmp_path` with the README's `dem.tif` standing for the sample DEM."""
    code = block.replace('"dem.tif"', repr(str(DEM)))
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        scope = {}
        exec(compile(code, "README.md", "exec"), scope)
    finally:
        os.chdir(cwd)
    return scope


def check_against_the_raster(tin, bound):
    """Every valid sample of the DEM (read by rasterio) within `bound` of the TIN, in
    numpy, with the vertices taken back to (column, row) through the raster's transform."""
    with rasterio.open(DEM) as ds:
        heights = ds.read(1, masked=True).astype(np.float64).filled(np.nan)
        inverse = ~ds.transform
    v = np.array(tin.vertices)
    cols, rows = inverse * (v[:, 0], v[:, 1])
    pixel = np.column_stack([np.rint(cols - 0.5), np.rint(rows - 0.5), v[:, 2]])
    assert np.allclose(pixel[:, :2], np.column_stack([cols - 0.5, rows - 0.5]), atol=1e-6)
    worst, covered = max_error_numpy(heights, pixel, tin.triangles)
    assert worst <= bound, worst
    assert covered > 0.9 * np.isfinite(heights).sum()
    assert abs(worst - tin.max_error) <= 1e-9 * max(1.0, worst)


def test_the_rasterio_example(tmp_path):
    scope = run_example(readme_block("With rasterio"), tmp_path)
    tin = scope["tin"]
    check_against_the_raster(tin, 1.0)
    written = trimesh.load(tmp_path / "tin.ply", process=False)
    assert len(written.faces) == len(tin) and len(written.vertices) == len(tin.vertices)
    # The CRS went into the file: PLY keeps it in a comment.
    header = (tmp_path / "tin.ply").read_bytes()[:4096]
    assert b"comment crs " in header and b"Albers" in header


def test_the_xarray_example(tmp_path):
    scope = run_example(readme_block("With xarray"), tmp_path)
    tin, mesh = scope["tin"], scope["mesh"]
    check_against_the_raster(tin, 1.0)
    assert np.array_equal(mesh.faces, tin.triangles)
