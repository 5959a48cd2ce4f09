"""The Python package against independent checks: the bound by numpy, files by trimesh and
other readers, bytes by the CLI."""

import doctest
import json
import os
import resource
import signal
import subprocess
import threading
import time
import xml.etree.ElementTree as ET

import affine
import numpy as np
import pytest
import shapely
import trimesh

import tinsmith
from conftest import REPO, domain_samples, max_error_numpy

FORMATS = ["ply", "obj", "stl", "glb", "geojson", "fgb", "landxml"]
EXTENSIONS = {"ply": "ply", "obj": "obj", "stl": "stl", "glb": "glb", "geojson": "geojson",
              "fgb": "fgb", "landxml": "xml"}


def bumps(rows=90, columns=120, seed=7):
    """A smooth random surface with some relief (floats)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:rows, 0:columns]
    z = 50 * np.sin(x / 9.0) * np.cos(y / 13.0) + 0.02 * (x - 60) ** 2
    return z + rng.normal(0, 0.3, size=z.shape)


# -- the bound, measured by numpy ---------------------------------------------------------


@pytest.mark.parametrize("eps,rows", [(1.0, 150), (5.0, 516), (30.0, 516)])
def test_bound_holds_on_the_sample_dem_by_numpy(becmodel, eps, rows):
    heights = becmodel[0][:rows]
    tin = tinsmith.mesh(heights, eps, tile_size=1024)
    worst, covered = max_error_numpy(heights, tin.vertices, tin.triangles)
    assert worst <= eps
    assert covered == heights.size
    assert tin.max_error <= eps
    assert abs(tin.max_error - worst) <= 1e-9 * max(1.0, worst)
    assert tin.report["triangles_after"] == len(tin) < 2 * 429 * (rows - 1)


def test_bound_holds_tiled_with_nodata_by_numpy(becmodel):
    heights, _, nodata = becmodel
    h = heights.copy()
    h[100:160, 50:90] = nodata  # a hole
    h[300:, 400:] = nodata  # a notch at the edge
    tin = tinsmith.mesh(h, 5.0, nodata=nodata, tile_size=200, threads=2)
    assert tin.report["tiles"]["count"] == 9
    f = np.where(h == nodata, np.nan, h.astype(np.float64))
    worst, covered = max_error_numpy(f, tin.vertices, tin.triangles)
    assert worst <= 5.0
    assert covered == domain_samples(~np.isnan(f))


def test_float64_arrays_are_read_in_place_when_nothing_needs_rewriting():
    z = bumps()
    z[10:14, 20:30] = np.nan
    before = z.copy()
    in_place = tinsmith.mesh(z, 1.0)
    assert in_place.report["heights_in_place"] is True
    assert np.array_equal(z, before, equal_nan=True)
    worst, _ = max_error_numpy(z, in_place.vertices, in_place.triangles)
    assert worst <= 1.0
    nothing_masked = np.ma.masked_array(z, mask=np.zeros(z.shape, dtype=bool))
    assert tinsmith.mesh(nothing_masked, 1.0).report["heights_in_place"] is True
    # Each of these needs its samples rewritten or converted: one copy, the same mesh.
    with_inf = z.copy()
    with_inf[10, 20] = np.inf
    copies = [
        tinsmith.mesh(np.asfortranarray(z), 1.0),
        tinsmith.mesh(z, 1.0, nodata=-9999.0),
        tinsmith.mesh(z, 1.0, mask=~np.isnan(z)),
        tinsmith.mesh(with_inf, 1.0),
        tinsmith.mesh(np.ma.masked_invalid(z), 1.0),
    ]
    for tin in copies:
        assert tin.report["heights_in_place"] is False
        assert np.array_equal(tin.vertices, in_place.vertices)
        assert np.array_equal(tin.triangles, in_place.triangles)
    assert tinsmith.mesh(z.astype(np.float32), 1.0).report["heights_in_place"] is False
    # Read in place for the tiled engine too, and the array outlives nothing it lent.
    big = bumps(700, 650)
    tiled = tinsmith.mesh(big, 2.0, tile_size=256, threads=2)
    assert tiled.report["heights_in_place"] is True and "tiles" in tiled.report
    assert np.array_equal(
        tiled.triangles, tinsmith.mesh(big.copy(order="F"), 2.0, tile_size=256).triangles
    )
    big.resize((10, 10), refcheck=True)  # nothing holds the buffer after the call


def test_same_mesh_for_one_and_two_threads(becmodel):
    heights, _, _ = becmodel
    one = tinsmith.mesh(heights, 2.0, tile_size=128, threads=1)
    two = tinsmith.mesh(heights, 2.0, tile_size=128, threads=2)
    assert np.array_equal(one.vertices, two.vertices)
    assert np.array_equal(one.triangles, two.triangles)


# -- arrays --------------------------------------------------------------------------------

DTYPES = [np.int8, np.uint8, np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64,
          np.float16, np.float32, np.float64]


@pytest.mark.parametrize("dtype", DTYPES)
def test_every_numeric_dtype_gives_the_float64_mesh(dtype):
    z = np.round(bumps(40, 50) / 4 + 40)  # whole numbers 0..127: exact in every dtype
    assert z.min() >= 0 and z.max() <= 127
    want = tinsmith.mesh(z, 1.0)
    got = tinsmith.mesh(z.astype(dtype), 1.0)
    assert np.array_equal(got.vertices, want.vertices)
    assert np.array_equal(got.triangles, want.triangles)


def test_non_contiguous_and_fortran_arrays_read_as_their_values():
    base = bumps(180, 240)
    for view in [base[::2, ::2], base[10:100, 20:200], np.asfortranarray(base), base.T]:
        assert not view.flags.c_contiguous or view is base
        want = tinsmith.mesh(np.ascontiguousarray(view), 0.5)
        got = tinsmith.mesh(view, 0.5)
        assert np.array_equal(got.vertices, want.vertices)
        assert np.array_equal(got.triangles, want.triangles)


def test_nan_nodata_mask_and_masked_arrays_agree():
    z = bumps()
    hole = np.zeros(z.shape, dtype=bool)
    hole[20:40, 30:70] = True
    hole[0, :] = True
    with_nan = np.where(hole, np.nan, z)
    with_inf = np.where(hole, np.inf, z)
    with_nodata = np.where(hole, -9999.0, z).astype(np.float32)
    want = tinsmith.mesh(with_nan, 1.0)
    others = [
        tinsmith.mesh(with_inf, 1.0),
        tinsmith.mesh(with_nodata, 1.0, nodata=-9999),
        tinsmith.mesh(z, 1.0, mask=~hole),
        tinsmith.mesh(np.ma.masked_array(z, mask=hole), 1.0),
    ]
    # float32 rounds the heights: same domain, heights within float32 of the others.
    for got in others:
        assert got.report["valid_samples"] == int((~hole).sum())
    for got in others[:1] + others[2:]:
        assert np.array_equal(got.triangles, want.triangles)
        assert np.array_equal(got.vertices, want.vertices)
    worst, covered = max_error_numpy(with_nan, want.vertices, want.triangles)
    assert worst <= 1.0 and covered == domain_samples(~hole)


def test_float32_nodata_compared_in_float32():
    z = bumps(30, 30).astype(np.float32)
    z[5:10, 5:10] = np.float32(-3.4028235e38)
    tin = tinsmith.mesh(z, 1.0, nodata=-3.4028235e38)
    assert tin.report["valid_samples"] == 900 - 25


@pytest.mark.parametrize("shape", [(1, 100), (100, 1), (1, 1)])
def test_a_single_row_or_column_is_a_clear_error(shape):
    with pytest.raises(ValueError, match="no 2x2 block of samples to triangulate"):
        tinsmith.mesh(np.zeros(shape), 1.0)


def test_other_shapes_and_dtypes_are_refused():
    with pytest.raises(ValueError, match="2D array"):
        tinsmith.mesh(np.zeros(10), 1.0)
    with pytest.raises(TypeError, match="real numeric dtype"):
        tinsmith.mesh(np.zeros((4, 4), dtype=bool), 1.0)
    with pytest.raises(TypeError, match="real numeric dtype"):
        tinsmith.mesh(np.zeros((4, 4), dtype=complex), 1.0)
    with pytest.raises(TypeError, match="boolean array"):
        tinsmith.mesh(np.zeros((4, 4)), 1.0, mask=np.ones((4, 4), dtype=np.uint8))
    with pytest.raises(ValueError, match="mask has shape"):
        tinsmith.mesh(np.zeros((4, 4)), 1.0, mask=np.ones((4, 5), dtype=bool))


def test_all_nodata_is_a_clear_error():
    with pytest.raises(ValueError, match="no 2x2 block of valid samples"):
        tinsmith.mesh(np.full((5, 5), np.nan), 1.0)


def test_a_huge_array_is_refused_before_allocation():
    # 60000 x 60000 float32 samples that take no memory (a broadcast view): meshing them
    # would need hundreds of GB.
    huge = np.broadcast_to(np.float32(1.0), (60000, 60000))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t = time.perf_counter()
    with pytest.raises(MemoryError, match="a 60000x60000 array needs about"):
        tinsmith.mesh(huge, 1.0, max_triangles=1000)
    with pytest.raises(MemoryError, match="is available"):
        tinsmith.mesh(huge, 1.0, tile_size=100000)
    with pytest.raises(MemoryError):
        tinsmith.verify(huge, np.zeros((3, 3)), np.zeros((1, 3)))
    assert time.perf_counter() - t < 1.0
    grown_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kib < 100_000, f"peak memory grew by {grown_kib} KiB"


# -- options and errors --------------------------------------------------------------------


def test_bad_options_are_value_errors_with_the_cli_names():
    z = bumps(20, 20)
    with pytest.raises(ValueError, match="invalid value 'fast' for error_model"):
        tinsmith.mesh(z, 1.0, error_model="fast")
    with pytest.raises(ValueError, match="max_error must be a finite number"):
        tinsmith.mesh(z, -1.0)
    with pytest.raises(ValueError, match="give max_error, or a count target"):
        tinsmith.mesh(z)
    with pytest.raises(ValueError, match="flip_rounds and extend_rounds work to an error bound"):
        tinsmith.mesh(z, max_triangles=10, flip_rounds=1)
    with pytest.raises(ValueError, match="singular"):
        tinsmith.mesh(z, 1.0, transform=(0, 0, 0, 0, 0, 0))
    with pytest.raises(ValueError, match="6 coefficients"):
        tinsmith.mesh(z, 1.0, transform=(0, 1, 0))
    assert issubclass(tinsmith.BoundError, Exception)


def test_count_targets():
    z = bumps()
    tin = tinsmith.mesh(z, max_triangles=500)
    assert len(tin) <= 500 and tin.report["order"] == "greedy"
    tin = tinsmith.mesh(z, max_vertices=300)
    assert len(tin.vertices) <= 300


def test_affine_objects_and_gdal_tuples_place_sample_centres():
    z = bumps(20, 30)
    by_tuple = tinsmith.mesh(z, 1.0, transform=(500000.0, 30.0, 0.0, 4100000.0, 0.0, -30.0))
    by_affine = tinsmith.mesh(z, 1.0, transform=affine.Affine(30.0, 0.0, 500000.0, 0.0, -30.0, 4100000.0))
    assert np.array_equal(by_affine.vertices, tinsmith.mesh(
        z, 1.0, transform=affine.Affine.from_gdal(500000.0, 30.0, 0.0, 4100000.0, 0.0, -30.0)).vertices)
    pixel = tinsmith.mesh(z, 1.0)
    assert np.array_equal(by_tuple.vertices, by_affine.vertices)
    assert np.array_equal(by_tuple.vertices[:, 0], 500000.0 + 30.0 * (pixel.vertices[:, 0] + 0.5))
    assert np.array_equal(by_tuple.vertices[:, 1], 4100000.0 - 30.0 * (pixel.vertices[:, 1] + 0.5))
    # Counter-clockwise (normals up) in the written coordinates either way.
    for tin in (by_tuple, pixel):
        v, t = tin.vertices, tin.triangles.astype(np.int64)
        a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        assert (cross > 0).all() if tin is by_tuple else (cross > 0).all() or (cross < 0).all()


def test_report_has_the_cli_report_fields():
    tin = tinsmith.mesh(bumps(), 1.0)
    r = tin.report
    for key in ["width", "height", "valid_samples", "max_error", "error_model", "order",
                "triangles_before", "triangles_after", "vertices_after", "max_error_bound",
                "measured_max_error", "start_vertices", "sweeps", "removal_attempts", "seconds"]:
        assert key in r, key
    assert r["width"] == 120 and r["height"] == 90 and r["max_error"] == 1.0
    assert r["measured_max_error"] == tin.max_error


def test_arrays_are_read_only():
    tin = tinsmith.mesh(bumps(20, 20), 1.0)
    with pytest.raises(ValueError):
        tin.vertices[0, 0] = 1.0


def test_verify_measures_and_catches_a_bad_mesh():
    z = bumps()
    tin = tinsmith.mesh(z, 1.0, transform=(0, 2, 0, 0, 0, -2))
    r = tinsmith.verify(z, tin.vertices, tin.triangles, 1.0, transform=(0, 2, 0, 0, 0, -2))
    assert r["passed"] and r["max_error"] == tin.max_error
    bad = tin.vertices.copy()
    bad[:, 2] += 1.5
    r = tinsmith.verify(z, bad, tin.triangles, 1.0, transform=(0, 2, 0, 0, 0, -2))
    assert not r["passed"] and r["max_error"] > 1.0 and r["problems"]
    r = tinsmith.verify(z, tin.vertices, tin.triangles[1:], 1.0, transform=(0, 2, 0, 0, 0, -2))
    assert not r["passed"] and r["open_edges"] > 0


def test_contour_lines_as_geojson_features():
    y, x = np.mgrid[0:41, 0:41]
    cone = np.hypot(x - 20.0, y - 20.0)
    lines = tinsmith.contour(cone, 5.0, transform=(0, 1, 0, 0, 0, -1))
    levels = sorted({f["properties"]["level"] for f in lines})
    assert levels == [5.0, 10.0, 15.0, 20.0, 25.0]  # the corners are 28.3 away
    ring = [f for f in lines if f["properties"]["level"] == 10.0]
    assert len(ring) == 1 and ring[0]["properties"]["closed"]
    pts = np.array(ring[0]["geometry"]["coordinates"])
    r = np.hypot(pts[:, 0] - 20.5, pts[:, 1] + 20.5)
    assert np.abs(r - 10).max() < 0.25
    decimated = tinsmith.contour(cone, 5.0, max_error=0.5)
    assert {f["properties"]["level"] for f in decimated} == set(levels)
    shapes = tinsmith.contour(cone, 5.0, transform=(0, 1, 0, 0, 0, -1), geometry="shapely")
    assert [level for level, _ in shapes] == [f["properties"]["level"] for f in lines]
    level, line = shapes[1]
    assert isinstance(line, shapely.LineString) and line.is_ring
    assert np.array_equal(np.asarray(line.coords), np.array(lines[1]["geometry"]["coordinates"]))


# -- files: every writer, read back by others ----------------------------------------------


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_writer_round_trips(tmp_path, becmodel, fmt):
    heights, transform, _ = becmodel
    tin = tinsmith.mesh(heights[:200, :150], 2.0, transform=transform)
    path = tmp_path / f"mesh.{EXTENSIONS[fmt]}"
    tin.write(path, crs="EPSG:3005")
    v, t = tin.vertices, tin.triangles
    if fmt in ("ply", "obj", "stl", "glb"):
        m = trimesh.load(path, process=False, force="mesh")
        if fmt in ("stl", "glb"):
            # float32 offsets from a local origin: STL keeps it in its header (which
            # trimesh ignores), glTF in the node translation (which trimesh applies, y up).
            got = m.vertices[m.faces].reshape(-1, 3)
            if fmt == "glb":
                got = np.stack([got[:, 0], -got[:, 2], got[:, 1]], axis=1)
            want = v[t].reshape(-1, 3)
            order_got = np.lexsort(got.T[::-1])
            order_want = np.lexsort(want.T[::-1])
            offset = want[order_want] - got[order_got]
            assert len(m.faces) == len(t)
            assert np.abs(offset - offset.mean(axis=0)).max() < 1e-3
        else:
            assert np.array_equal(m.faces, t)
            assert np.array_equal(m.vertices, v)
    elif fmt == "geojson":
        features = json.loads(path.read_text())["features"]
        assert len(features) == len(t)
        ring = np.array(features[0]["geometry"]["coordinates"][0])
        assert np.array_equal(ring[:3], v[t[0]])
    elif fmt == "landxml":
        ns = {"x": "http://www.landxml.org/schema/LandXML-1.2"}
        root = ET.parse(path).getroot()
        faces = root.findall(".//x:F", ns)
        points = root.findall(".//x:P", ns)
        assert len(faces) == len(t) and len(points) == len(v)
    elif fmt == "fgb":
        out = subprocess.run(["ogr2ogr", "-f", "GeoJSON", "/vsistdout/", str(path)],
                             capture_output=True, text=True, check=True).stdout
        assert len(json.loads(out)["features"]) == len(t)
    if fmt in ("obj", "stl", "glb"):
        assert (tmp_path / "mesh.prj").read_text() == "EPSG:3005"


def test_float32_formats_refuse_what_would_break_the_bound(tmp_path):
    # Heights 1e6..1.3e6 are stored as float32 offsets of up to 1.5e5 from a mid-range
    # origin, in steps of 1/64: the corners (off the steps by 0.0015) cannot keep 0.001.
    z = 1e6 + 0.123456 + np.linspace(0, 3e5, 400).reshape(20, 20)
    tin = tinsmith.mesh(z, 0.001)
    with pytest.raises(tinsmith.BoundError, match="float32 heights round by up to"):
        tin.write(tmp_path / "m.stl")
    assert not (tmp_path / "m.stl").exists()
    tin.write(tmp_path / "m.ply")  # double precision keeps it
    # Positions: 60,000 samples across (0.3 apart) cannot all be placed in float32 within
    # the verifier's 1e-3 pixel of their sample.
    wide = tinsmith.mesh(np.zeros((2, 60000)), 0.0, max_edge_length=2,
                         transform=(0.0, 0.3, 0.0, 0.0, 0.0, -0.3))
    with pytest.raises(ValueError, match="would not map back to its sample in float32"):
        wide.write(tmp_path / "w.glb")


def test_unknown_format_names_the_choices(tmp_path):
    tin = tinsmith.mesh(bumps(10, 10), 1.0)
    with pytest.raises(ValueError, match="mesh.xyz"):
        tin.write(tmp_path / "mesh.xyz")


def test_trimesh_view():
    tin = tinsmith.mesh(bumps(), 1.0)
    m = tin.to_trimesh()
    assert np.array_equal(m.faces, tin.triangles) and np.array_equal(m.vertices, tin.vertices)


# -- the same bytes as the CLI -------------------------------------------------------------


@pytest.mark.parametrize(
    "name,args,kwargs",
    [
        ("tiled.ply", ["--max-error", "5"], dict(max_error=5.0)),
        ("whole.ply", ["--max-error", "2", "--tile-size", "1024"], dict(max_error=2.0, tile_size=1024)),
        ("count.obj", ["--max-triangles", "5000"], dict(max_triangles=5000)),
        ("tiled.fgb", ["--max-error", "10", "--threads", "1", "--tile-size", "300"],
         dict(max_error=10.0, threads=1, tile_size=300)),
        ("whole.stl", ["--max-error", "3", "--tile-size", "1024"],
         dict(max_error=3.0, tile_size=1024, format="stl")),
        ("samples.glb", ["--max-error", "0.5", "--tile-size", "1024", "--vertex-heights", "samples"],
         dict(max_error=0.5, tile_size=1024, format="glb", vertex_heights="samples")),
        ("tiled.glb", ["--max-error", "1"], dict(max_error=1.0, format="glb")),
        ("solid.stl", ["--max-error", "3", "--base", "-50"],
         dict(max_error=3.0, format="stl", write=dict(base=-50.0))),
        ("normals.glb", ["--max-error", "2", "--normals"],
         dict(max_error=2.0, format="glb", write=dict(normals=True))),
    ],
)
def test_same_bytes_as_the_cli(tmp_path, becmodel, cli, name, args, kwargs):
    write = kwargs.pop("write", {})
    heights, transform, nodata = becmodel
    dem = REPO / "data" / "becmodel_dem_bc_albers_50m.tif"
    by_cli = tmp_path / f"cli-{name}"
    subprocess.run([str(cli), "mesh", str(dem), "-o", str(by_cli), "-q", *args], check=True)
    # The CRS text as GDAL gave it to the CLI (PLY's comment, the OBJ's .prj, ...).
    crs = subprocess.run([str(cli), "info", str(dem), "--json"], capture_output=True, text=True,
                         check=True).stdout
    wkt = json.loads(crs)["crs_wkt"]
    tin = tinsmith.mesh(heights, nodata=nodata, transform=transform, **kwargs)
    by_package = tmp_path / f"package-{name}"
    tin.write(by_package, crs=wkt, **write)
    assert by_package.read_bytes() == by_cli.read_bytes()


def test_base_and_normals_belong_to_their_formats(tmp_path):
    tin = tinsmith.mesh(bumps(), 1.0, format="stl")
    lowest = float(tin.vertices[:, 2].min())
    with pytest.raises(ValueError, match="base applies to STL output only"):
        tin.write(tmp_path / "m.ply", base=lowest - 1)
    with pytest.raises(ValueError, match="normals applies to glTF output only"):
        tin.write(tmp_path / "m.stl", normals=True)
    with pytest.raises(ValueError, match="below the lowest vertex"):
        tin.write(tmp_path / "m.stl", base=lowest)
    assert not list(tmp_path.iterdir())
    tin.write(tmp_path / "m.stl", base=lowest - 1)
    solid = trimesh.load(tmp_path / "m.stl")
    # STL holds offsets from a local origin: the floor sits 1 below the lowest vertex and
    # the solid spans from it to the highest.
    highest = float(tin.vertices[:, 2].max())
    assert solid.is_watertight
    assert solid.extents[2] == pytest.approx(highest - lowest + 1, abs=1e-3)


# -- the GIL and Ctrl-C ---------------------------------------------------------------------


def slow_heights(size=700):
    return np.random.default_rng(1).normal(0, 100, size=(size, size))


def test_the_gil_is_released_while_decimating():
    z = slow_heights()
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    try:
        tinsmith.mesh(z, max_triangles=20000)
    finally:
        done.set()
        t.join()
    elapsed = time.perf_counter() - start
    assert elapsed > 0.3, "the call was too short to tell"
    # Held, the GIL would have stopped the ticker for the whole call.
    assert len([x for x in ticks if x > start + 0.05]) > 10


@pytest.mark.parametrize("tiles", [dict(tile_size=4096), dict(tile_size=256, threads=2)])
def test_ctrl_c_interrupts_a_long_call(tiles):
    # About 6 s on this machine uninterrupted in one piece (2.1 M triangles kept), 5 s in
    # 36 tiles on 2 threads.
    z = slow_heights(1500)
    # Python raises KeyboardInterrupt only where SIGINT has its default handler; a process
    # started in the background by a shell inherits SIGINT ignored.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            tinsmith.mesh(z, 50.0, **tiles)
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    elapsed = time.perf_counter() - start
    assert elapsed < 2.0, f"interrupted only after {elapsed:.1f} s"
    # The package is usable afterwards.
    assert len(tinsmith.mesh(z[:50, :50], 50.0)) > 0


def test_ctrl_c_interrupts_the_start_mesh():
    # A count target on 4000 x 4000 samples: about 2.5 s building its start mesh (the
    # RTINs it tries) on this machine before the first removal.
    rng = np.random.default_rng(1)
    z = np.cumsum(np.cumsum(rng.normal(0, 1, size=(4000, 4000)), 0), 1)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            tinsmith.mesh(z, max_triangles=200_000)
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    elapsed = time.perf_counter() - start
    assert elapsed < 1.5, f"interrupted only after {elapsed:.1f} s"


# -- doctests ---------------------------------------------------------------------------------


def test_docstring_examples_run():
    result = doctest.testmod(tinsmith, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 6 and result.failed == 0
