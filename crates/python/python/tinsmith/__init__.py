"""DEMs and other 2D scalar grids to TINs within a guaranteed vertical error bound.

``tinsmith.mesh`` decimates a 2D numpy array (Schikore & Bajaj vertex removal, as the
``tinsmith`` command line does) and returns a :class:`Tin` whose linear interpolation is
within ``max_error`` of every valid sample: the independent verifier has measured it
before the call returns. Rasters are read by your own tools (rasterio, xarray); the package
links no GDAL.

>>> import numpy as np
>>> import tinsmith
>>> y, x = np.mgrid[0:64, 0:64]
>>> heights = np.hypot(x - 32, y - 32)          # a cone, 64 x 64 samples
>>> tin = tinsmith.mesh(heights, max_error=0.5)
>>> tin.max_error <= 0.5
True
>>> tin.vertices.shape[1], tin.triangles.dtype
(3, dtype('uint32'))
>>> len(tin) < 2 * 63 * 63                       # far fewer than the full grid's
True
>>> mesh = tin.to_trimesh()                      # when trimesh is installed
>>> len(mesh.faces) == len(tin)
True
"""

from __future__ import annotations

import numbers
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _tinsmith
from ._tinsmith import DEFAULT_TILE_SIZE, BoundError, Tin

__all__ = ["mesh", "verify", "contour", "Tin", "BoundError", "DEFAULT_TILE_SIZE"]

Transform = Union[Sequence[float], Any]

# float16 has no Rust type on this side: widened to float64 first (a copy).
_CONVERTED = (np.float16,)


def _heights(heights: Any, mask: Any) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """The array to read (no copy for a numpy array of a supported dtype, whatever its
    strides) and the validity mask (True = valid), a numpy masked array's mask included."""
    if isinstance(heights, np.ma.MaskedArray):
        invalid = np.ma.getmaskarray(heights)
        if invalid.any():
            valid = ~invalid
            mask = valid if mask is None else (np.asarray(mask, dtype=bool) & valid)
        # Nothing masked: the data alone (a float64 array is then read in place).
        heights = heights.data
    # xarray.DataArray and anything else array-like.
    array = np.asarray(heights)
    if array.dtype == np.bool_ or not np.issubdtype(array.dtype, np.number) or np.issubdtype(
        array.dtype, np.complexfloating
    ):
        raise TypeError(f"heights must have a real numeric dtype (float or integer), got {array.dtype}")
    if array.dtype.type in _CONVERTED:
        array = array.astype(np.float64)
    if not array.dtype.isnative:
        array = array.astype(array.dtype.newbyteorder("="))
    if mask is not None:
        mask = np.asarray(mask)
        if mask.dtype != np.bool_:
            raise TypeError(
                f"mask must be a boolean array (True = valid sample), got {mask.dtype}; "
                "for a GDAL-style 0/255 mask pass mask != 0"
            )
    return array, mask


def _transform(transform: Optional[Transform]) -> Optional[Tuple[float, ...]]:
    """A GDAL-order 6-tuple (c, a, b, f, d, e) from a 6-sequence in GDAL order or an
    ``affine.Affine`` (duck-typed: anything with .a .b .c .d .e .f)."""
    if transform is None:
        return None
    if all(hasattr(transform, k) for k in "abcdef"):
        t = transform
        return (float(t.c), float(t.a), float(t.b), float(t.f), float(t.d), float(t.e))
    values = tuple(float(v) for v in transform)
    if len(values) != 6:
        raise ValueError(
            f"transform must have 6 coefficients (GDAL order: x0, dx, rx, y0, ry, dy), got {len(values)}"
        )
    return values


def _nodata(nodata: Optional[float]) -> Optional[float]:
    if nodata is None:
        return None
    if not isinstance(nodata, numbers.Real):
        raise TypeError(f"nodata must be a number, got {type(nodata).__name__}")
    return float(nodata)


def mesh(
    heights: Any,
    max_error: Optional[float] = None,
    *,
    nodata: Optional[float] = None,
    mask: Any = None,
    transform: Optional[Transform] = None,
    max_triangles: Optional[int] = None,
    max_vertices: Optional[int] = None,
    error_model: str = "exact",
    selection: str = "hybrid",
    order: str = "sweep",
    retriangulate: str = "dp",
    dp_max_ring: int = 8,
    initial_mesh: str = "auto",
    max_edge_length: Optional[int] = None,
    flip_rounds: int = 0,
    extend_rounds: int = 0,
    vertex_heights: str = "raised",
    contour_interval: Optional[float] = None,
    contour_offset: Optional[float] = None,
    contour_levels: Optional[Iterable[float]] = None,
    tile_size: int = DEFAULT_TILE_SIZE,
    threads: Optional[int] = None,
    format: Optional[str] = None,
) -> Tin:
    """Decimate ``heights`` into a TIN within ``max_error`` of every valid sample.

    The arguments are ``tinsmith mesh``'s options, with the same names (``-`` as ``_``),
    meanings and defaults; see ``tinsmith mesh --help`` and docs/python.md.

    heights
        A 2D array (rows, columns) of any real numeric dtype: float64/32, int8..64,
        uint8..64 are read as they lie in memory (C or Fortran order, any strides, no
        conversion copy); float16 is widened to float64 first. A numpy masked array's
        mask marks nodata; ``xarray.DataArray`` works through ``np.asarray``. A C-order
        float64 array with no ``nodata``, no ``mask`` (nothing masked) and no infinities
        is read in place, not copied (``report["heights_in_place"]``); any other array is
        read once into the decimator's float64 grid. Do not write to the array from
        another thread during the call.
    max_error
        The bound: every valid sample is within it of the TIN (``None`` with a count
        target).
    nodata
        Samples equal to this (compared in the array's dtype) are nodata; NaN and
        infinities always are.
    mask
        Boolean array of the same shape, ``True`` where the sample is valid.
    transform
        Sample (column, row) to world: a GDAL-order 6-tuple ``(x0, dx, rx, y0, ry, dy)``
        or an ``affine.Affine`` (rasterio's ``dataset.transform``). Vertices are then
        world coordinates of sample centres; without it, (column, row, value).
    max_triangles, max_vertices
        Count targets (greedy order, whole array at once).
    tile_size, threads
        Arrays larger than ``tile_size`` a side are meshed tile by tile on ``threads``
        workers (``None``/0: one per core) into one welded mesh, as the CLI does.
    format
        The format the mesh will be written in (``--format``): for ``stl`` and ``glb``,
        whose float32 heights round, decimation keeps ``max_error`` less that rounding, as
        the CLI does, so that the file keeps ``max_error``.

    Returns a :class:`Tin`. Raises ``ValueError`` for bad arguments (the CLI's messages),
    ``MemoryError`` before allocating when the array cannot fit, ``BoundError`` if the
    mesh ever failed its own verification, ``KeyboardInterrupt`` on Ctrl-C.

    >>> import numpy as np, tinsmith
    >>> heights = np.arange(12, dtype=np.int16).reshape(3, 4) * 10   # a plane
    >>> tin = tinsmith.mesh(heights, 0.0, transform=(500000, 30, 0, 4100000, 0, -30))
    >>> tin.triangles.shape                           # a plane needs two triangles
    (2, 3)
    >>> float(tin.vertices[:, 0].min()), float(tin.vertices[:, 1].max())   # sample centres
    (500015.0, 4099985.0)
    >>> tin.report["measured_max_error"]
    0.0
    """
    array, mask = _heights(heights, mask)
    choices = {
        "max_error": None if max_error is None else float(max_error),
        "max_triangles": max_triangles,
        "max_vertices": max_vertices,
        "error_model": error_model,
        "selection": selection,
        "order": order,
        "retriangulate": retriangulate,
        "dp_max_ring": dp_max_ring,
        "initial_mesh": initial_mesh,
        "max_edge_length": max_edge_length,
        "flip_rounds": flip_rounds,
        "extend_rounds": extend_rounds,
        "vertex_heights": vertex_heights,
        "contour_interval": contour_interval,
        "contour_offset": contour_offset,
        "contour_levels": None if contour_levels is None else [float(v) for v in contour_levels],
        "tile_size": tile_size,
        "threads": threads,
        "format": format,
    }
    return _tinsmith.mesh(array, choices, _nodata(nodata), mask, _transform(transform))


def verify(
    heights: Any,
    vertices: Any,
    triangles: Any,
    max_error: Optional[float] = None,
    *,
    nodata: Optional[float] = None,
    mask: Any = None,
    transform: Optional[Transform] = None,
) -> Dict[str, Any]:
    """Measure any TIN of ``heights`` with the independent verifier, as ``tinsmith
    verify`` measures a mesh file: the true error at every valid sample, coverage of the
    domain, orientation and conformity. ``vertices`` (N x 3) must sit on sample centres
    (through ``transform``, as ``mesh`` writes them); ``triangles`` (M x 3) index them,
    counter-clockwise in those coordinates. Returns the verifier's report as a dict
    (``passed``, ``max_error``, ``max_error_at``, ``problems``, ...).

    >>> import numpy as np, tinsmith
    >>> heights = np.array([[0.0, 1.0], [1.0, 2.0]])
    >>> r = tinsmith.verify(heights, [[0, 0, 0], [1, 0, 1], [0, 1, 1], [1, 1, 2]],
    ...                     [[0, 1, 2], [1, 3, 2]], max_error=0.1)
    >>> r["passed"], r["max_error"]
    (True, 0.0)
    """
    array, mask = _heights(heights, mask)
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    t = np.ascontiguousarray(triangles, dtype=np.int64)
    if v.ndim != 2 or t.ndim != 2:
        raise ValueError("vertices must be N x 3 (x, y, z) and triangles M x 3 (indices)")
    return _tinsmith.verify(
        array, v, t, None if max_error is None else float(max_error), _nodata(nodata), mask, _transform(transform)
    )


def contour(
    heights: Any,
    interval: Optional[float] = None,
    *,
    levels: Optional[Iterable[float]] = None,
    offset: Optional[float] = None,
    max_error: Optional[float] = None,
    simplify: Optional[float] = None,
    nodata: Optional[float] = None,
    mask: Any = None,
    transform: Optional[Transform] = None,
    geometry: str = "geojson",
) -> List[Any]:
    """Contour lines of ``heights`` every ``interval`` (plus ``offset``) or at ``levels``,
    traced as ``tinsmith contour`` traces them: on the full grid's TIN, or on the TIN
    decimated within ``max_error``; ``simplify`` (Douglas-Peucker, in output units).

    Returns GeoJSON-like Feature dicts (``{"type": "Feature", "geometry": {"type":
    "LineString", ...}, "properties": {"level": ..., "closed": ...}}``), or, with
    ``geometry="shapely"``, ``(level, shapely.LineString)`` pairs (shapely must be
    importable).

    >>> import numpy as np, tinsmith
    >>> y, x = np.mgrid[0:5, 0:5]
    >>> lines = tinsmith.contour(np.hypot(x - 2.0, y - 2.0), levels=[1.5])
    >>> len(lines), lines[0]["properties"]["closed"]
    (1, True)
    """
    if geometry not in ("geojson", "shapely"):
        raise ValueError(f"geometry must be 'geojson' or 'shapely', got {geometry!r}")
    array, mask = _heights(heights, mask)
    lines = _tinsmith.contour(
        array,
        None if interval is None else float(interval),
        None if levels is None else [float(v) for v in levels],
        None if offset is None else float(offset),
        None if max_error is None else float(max_error),
        None if simplify is None else float(simplify),
        _nodata(nodata),
        mask,
        _transform(transform),
    )
    if geometry == "shapely":
        import shapely

        return [(level, shapely.LineString(points)) for level, _closed, points in lines]
    return [
        {
            "type": "Feature",
            "geometry": {"type": "LineString", "coordinates": [list(p) for p in points]},
            "properties": {"level": level, "closed": closed},
        }
        for level, closed, points in lines
    ]

