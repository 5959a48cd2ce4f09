//! `sample_geographic`: each sample depends only on the raster and the point's position,
//! so any window of a lattice gets the same bits as the whole lattice (checked on
//! projected rasters, global rasters in every longitude frame, a raster east of 180°,
//! nodata holes, lattices coarser than the raster); the frame a raster is stored in does
//! not matter; and the samples agree with GDAL's own exact bilinear warp (`gdalwarp -et 0
//! -r bilinear`) wherever both have all four pixels.

use std::path::{Path, PathBuf};
use std::process::Command;

use gdal::raster::{Buffer, RasterCreationOptions};
use gdal::spatial_ref::SpatialRef;
use gdal::{Dataset, DriverManager};
use tinsmith_raster::{geographic_bounds, open_info, sample_geographic, GeoLattice, VerticalDatum};

fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The global lattice of the first terrain level at least as fine as the raster, `coarser`
/// times coarser, over the raster's bounds and a sample beyond.
fn lattice_over(path: &Path, coarser: f64) -> GeoLattice {
    let bounds = geographic_bounds(path, 1).expect("bounds");
    let d = coarser
        * (0..24)
            .map(|l| 180.0 / (217.0 * (1u64 << l) as f64))
            .find(|&d| d <= bounds.resolution)
            .expect("a fine enough level");
    let i0 = (((bounds.west + 180.0) / d).floor() - 1.0).max(0.0);
    let j0 = (((bounds.south + 90.0) / d).floor() - 1.0).max(0.0);
    GeoLattice {
        latitudes: tinsmith_raster::Latitudes::Uniform,
        west: -180.0,
        south: -90.0,
        step: d,
        first_column: i0 as u64,
        first_row: j0 as u64,
        width: (((bounds.east + 180.0) / d).ceil() - i0 + 2.0) as u32,
        height: (((bounds.north + 90.0) / d).ceil() - j0 + 2.0) as u32,
    }
}

/// A small deterministic generator (a 64-bit LCG) for the windows.
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: u32) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % u64::from(n.max(1))) as u32
    }
}

/// Windows of `lattice`: `(column, row, width, height)` inside it, of every shape from a
/// single point to most of it, and the points on a few chosen columns alone.
fn windows(lattice: &GeoLattice, seed: u64, columns: &[u32]) -> Vec<(u32, u32, u32, u32)> {
    let (w, h) = (lattice.width, lattice.height);
    let mut rng = Lcg(seed);
    let mut out = vec![(0, 0, w, h)];
    for k in 0..24 {
        let (cw, ch) = match k % 4 {
            0 => (1, 1),
            1 => (1 + rng.below(w), 1),
            2 => (1 + rng.below(w.min(100)), 1 + rng.below(h.min(100))),
            _ => (1 + rng.below(w), 1 + rng.below(h)),
        };
        out.push((rng.below(w - cw + 1), rng.below(h - ch + 1), cw, ch));
    }
    for &c in columns {
        out.push((c, rng.below(h), 1, 1));
        out.push((c.saturating_sub(1), 0, 2.min(w - c.saturating_sub(1)), h));
    }
    out
}

/// Samples `lattice` whole and in many windows (positions from the same global indices),
/// and checks every window's samples are the whole lattice's, bit for bit. Returns the
/// whole lattice's samples.
fn check_windows(path: &Path, lattice: &GeoLattice, seed: u64, columns: &[u32]) -> Vec<f32> {
    let whole = sample_geographic(path, 1, lattice, &VerticalDatum::Ellipsoid, f32::NAN)
        .expect("whole lattice");
    let valid = whole.iter().filter(|v| v.is_finite()).count();
    assert!(valid > 0, "{}: no sample", path.display());
    assert!(valid < whole.len(), "{}: no sample beyond", path.display());
    for (c0, r0, w, h) in windows(lattice, seed, columns) {
        let window = GeoLattice {
            first_column: lattice.first_column + u64::from(c0),
            first_row: lattice.first_row + u64::from(r0),
            width: w,
            height: h,
            ..*lattice
        };
        let part = sample_geographic(path, 1, &window, &VerticalDatum::Ellipsoid, f32::NAN)
            .expect("window");
        for j in 0..h {
            for i in 0..w {
                let a = part[(j * w + i) as usize];
                let b = whole[((r0 + j) * lattice.width + c0 + i) as usize];
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "{}: point ({}, {}) of window {c0},{r0} {w}x{h}: {a} alone, {b} whole",
                    path.display(),
                    c0 + i,
                    r0 + j
                );
            }
        }
    }
    whole
}

#[test]
fn projected_rasters_sample_the_same_in_any_window() {
    for (k, name) in [
        "tests/fixtures/tintn_valid_raster_3857.tif",
        "../../data/becmodel_dem_bc_albers_50m.tif",
    ]
    .iter()
    .enumerate()
    {
        let path = fixture(name);
        // At the finest terrain level, and 5.3 times coarser (windows split to the pixels
        // around their points).
        for (coarser, seed) in [(1.0, 1), (5.3, 2)] {
            check_windows(
                &path,
                &lattice_over(&path, coarser),
                seed + 10 * k as u64,
                &[],
            );
        }
    }
}

/// Writes a 72 x 36 Float32 EPSG:4326 raster of 5° pixels whose west edge is `west`, with
/// nodata -9999.
fn write_global(path: &Path, west: f64, values: Vec<f32>) {
    let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
    let mut ds = driver
        .create_with_band_type_with_options::<f32, _>(
            path,
            72,
            36,
            1,
            &RasterCreationOptions::default(),
        )
        .expect("create");
    ds.set_geo_transform(&[west, 5.0, 0.0, 90.0, 0.0, -5.0])
        .expect("geotransform");
    ds.set_spatial_ref(&SpatialRef::from_epsg(4326).expect("EPSG:4326"))
        .expect("CRS");
    let mut band = ds.rasterband(1).expect("band");
    band.set_no_data_value(Some(-9999.0)).expect("nodata");
    let mut buffer = Buffer::new((72, 36), values);
    band.write((0, 0), (72, 36), &mut buffer).expect("write");
}

/// Column `i`, row `j` of the global test raster stored from 0° east: smooth, with a
/// nodata hole around column 50, row 20.
fn global_value(i: usize, j: usize) -> f32 {
    if (i as f32 - 50.0).abs() < 3.0 && (j as f32 - 20.0).abs() < 2.0 {
        return -9999.0;
    }
    let lon = (i as f32 + 0.5) * 5.0_f32.to_radians();
    300.0 * (3.0 * lon).sin() + 40.0 * ((i * 7 + j * 13) % 11) as f32 + 3.0 * j as f32
}

/// The global test raster in 0..360°, -360..0° and -180..180° (the same values rolled).
fn global_rasters(dir: &Path) -> [PathBuf; 3] {
    let in_0_360: Vec<f32> = (0..72 * 36).map(|k| global_value(k % 72, k / 72)).collect();
    let in_180: Vec<f32> = (0..72 * 36)
        .map(|k| global_value((k % 72 + 36) % 72, k / 72))
        .collect();
    let paths = ["0_360.tif", "-360_0.tif", "180.tif"].map(|name| dir.join(name));
    write_global(&paths[0], 0.0, in_0_360.clone());
    write_global(&paths[1], -360.0, in_0_360);
    write_global(&paths[2], -180.0, in_180);
    paths
}

#[test]
fn global_rasters_in_any_frame_sample_the_same_in_any_window() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (k, path) in global_rasters(dir.path()).iter().enumerate() {
        for (coarser, seed) in [(1.0, 3), (7.1, 4)] {
            let lattice = lattice_over(path, coarser);
            // The columns at the raster's seam (0° or ±180°) and at the antimeridian.
            let seam: Vec<u32> = [0.0, 180.0, -180.0]
                .iter()
                .map(|lon| ((lon + 180.0) / lattice.step) as i64 - lattice.first_column as i64)
                .filter(|&c| c >= 1 && c < i64::from(lattice.width) - 1)
                .map(|c| c as u32)
                .collect();
            let whole = check_windows(path, &lattice, seed + 10 * k as u64, &seed_columns(&seam));
            // A turn is a whole number of the finest level's steps: the same lattice a turn
            // east is the same columns, with the same bits.
            if coarser == 1.0 {
                let turn = (360.0 / lattice.step).round() as u64;
                for turns in [1, 3] {
                    let east = GeoLattice {
                        first_column: lattice.first_column + turns * turn,
                        ..lattice
                    };
                    let again =
                        sample_geographic(path, 1, &east, &VerticalDatum::Ellipsoid, f32::NAN)
                            .expect("a turn east");
                    let differ = (0..whole.len())
                        .filter(|&k| {
                            whole[k].to_bits() != again[k].to_bits()
                                && !(whole[k].is_nan() && again[k].is_nan())
                        })
                        .count();
                    assert_eq!(differ, 0, "{}: {turns} turns east", path.display());
                }
            }
        }
    }
}

/// The columns given and their neighbours.
fn seed_columns(columns: &[u32]) -> Vec<u32> {
    columns.iter().flat_map(|&c| [c - 1, c, c + 1]).collect()
}

/// Both nodata, or equal but for float rounding of the position in the raster's frame (a
/// longitude moved by a turn rounds differently).
fn same(a: f32, b: f32) -> bool {
    if a.is_nan() || b.is_nan() {
        return a.is_nan() && b.is_nan();
    }
    (a - b).abs() <= 4.0 * f32::EPSILON * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn a_global_raster_samples_alike_in_0_to_360_minus_360_to_0_and_minus_180_to_180() {
    // GDAL's warper saw the 0° meridian of a 0..360 raster as an edge (samples within
    // half a pixel west of it got the edge value), and the ±180° one of a -180..180 raster
    // too; its kernel for a lattice coarser than the raster followed each view's size.
    // Every column of a global raster now has both neighbours, at any spacing.
    let dir = tempfile::tempdir().expect("tempdir");
    let [east, far_west, west] = global_rasters(dir.path());
    for step in [1.25, 4.5, 11.0] {
        let width = (360.0 / step) as u32 + 1;
        let lattice = GeoLattice {
            latitudes: tinsmith_raster::Latitudes::Uniform,
            west: -180.0,
            south: -88.0,
            step,
            first_column: 0,
            first_row: 0,
            width,
            height: (176.0 / step) as u32 + 1,
        };
        let b = sample_geographic(&west, 1, &lattice, &VerticalDatum::Ellipsoid, f32::NAN)
            .expect("-180..180");
        // A sample everywhere but around the nodata hole (235..265°, -22.5..-2.5°), next
        // to 0° and ±180° too.
        for (k, v) in b.iter().enumerate() {
            let (lon, lat) = (lattice.lon(k as u32 % width), lattice.lat(k as u32 / width));
            let hole = (-130.0..=-90.0).contains(&lon) && (-27.5..=2.5).contains(&lat);
            assert!(
                v.is_finite() || hole,
                "step {step}: nothing at ({lon}, {lat})"
            );
        }
        for source in [&east, &far_west] {
            let a = sample_geographic(source, 1, &lattice, &VerticalDatum::Ellipsoid, f32::NAN)
                .expect("0..360");
            let differ: Vec<usize> = (0..a.len()).filter(|&k| !same(a[k], b[k])).collect();
            assert!(
                differ.is_empty(),
                "{}, step {step}: {} of {} samples differ, first at longitude {}: {} vs {}",
                source.display(),
                differ.len(),
                a.len(),
                lattice.lon(differ[0] as u32 % width),
                a[differ[0]],
                b[differ[0]]
            );
        }
    }
}

#[test]
fn a_raster_east_of_180_samples_as_the_same_raster_west_of_it() {
    // 40 x 20 pixels of 0.25°, stored from 185° east (the far part of a 0..360 grid) and
    // from -175°: the same place, sampled alike on a lattice in either frame, and the same
    // in any window.
    let dir = tempfile::tempdir().expect("tempdir");
    let values: Vec<f32> = (0..40 * 20)
        .map(|k| {
            let (i, j) = ((k % 40) as f32, (k / 40) as f32);
            if (i - 30.0).abs() < 2.0 && (j - 5.0).abs() < 2.0 {
                -9999.0
            } else {
                50.0 * (i * 0.4).sin() + 3.0 * j * j
            }
        })
        .collect();
    let write = |name: &str, west: f64| {
        let path = dir.path().join(name);
        let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
        let mut ds = driver
            .create_with_band_type_with_options::<f32, _>(
                &path,
                40,
                20,
                1,
                &RasterCreationOptions::default(),
            )
            .expect("create");
        ds.set_geo_transform(&[west, 0.25, 0.0, -30.0, 0.0, -0.25])
            .expect("geotransform");
        ds.set_spatial_ref(&SpatialRef::from_epsg(4326).expect("EPSG:4326"))
            .expect("CRS");
        let mut band = ds.rasterband(1).expect("band");
        band.set_no_data_value(Some(-9999.0)).expect("nodata");
        let mut buffer = Buffer::new((40, 20), values.clone());
        band.write((0, 0), (40, 20), &mut buffer).expect("write");
        path
    };
    let (east, west) = (write("east.tif", 185.0), write("west.tif", -175.0));
    for lon0 in [-176.0, 184.0] {
        let lattice = GeoLattice {
            latitudes: tinsmith_raster::Latitudes::Uniform,
            west: lon0,
            south: -36.0,
            step: 0.0625,
            first_column: 0,
            first_row: 0,
            width: 193,
            height: 97,
        };
        let a = check_windows(&east, &lattice, 5, &[]);
        let b = sample_geographic(&west, 1, &lattice, &VerticalDatum::Ellipsoid, f32::NAN)
            .expect("west");
        assert!(a.iter().filter(|v| v.is_finite()).count() > 10_000);
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(
                same(*x, *y),
                "from {lon0}: point {k}: {x} east of 180, {y} west"
            );
        }
    }
}

/// `gdalwarp -et 0 -r bilinear` of `path` onto `lattice` (pixel centres on its points),
/// row 0 the southernmost, NaN where GDAL leaves nodata.
fn gdalwarp_samples(dir: &Path, path: &Path, lattice: &GeoLattice) -> Vec<f64> {
    let out = dir.join("warped.tif");
    let d = lattice.step;
    let (west, south) = (lattice.lon(0), lattice.lat(0));
    let (east, north) = (
        lattice.lon(lattice.width - 1),
        lattice.lat(lattice.height - 1),
    );
    let status = Command::new("gdalwarp")
        .args(["-q", "-overwrite", "-et", "0", "-t_srs", "EPSG:4326"])
        .args([
            "-r",
            "bilinear",
            "-ot",
            "Float64",
            "-dstnodata",
            "-99999",
            "-te",
        ])
        .args(
            [
                west - d / 2.0,
                south - d / 2.0,
                east + d / 2.0,
                north + d / 2.0,
            ]
            .map(|v| format!("{v:.17}")),
        )
        .args([
            "-ts",
            &lattice.width.to_string(),
            &lattice.height.to_string(),
        ])
        .arg(path)
        .arg(&out)
        .status()
        .expect("gdalwarp (Debian gdal-bin, installed by `make deps`) must be on PATH");
    assert!(status.success());
    let ds = Dataset::open(&out).expect("warped");
    let (w, h) = (lattice.width as usize, lattice.height as usize);
    let values = ds
        .rasterband(1)
        .expect("band")
        .read_as::<f64>((0, 0), (w, h), (w, h), None)
        .expect("read")
        .into_shape_and_vec()
        .1;
    let mut rows: Vec<f64> = values.chunks_exact(w).rev().flatten().copied().collect();
    for v in &mut rows {
        if *v == -99999.0 {
            *v = f64::NAN;
        }
    }
    rows
}

/// Each point's position in the raster (column, row from its top-left corner, in pixels),
/// by PROJ through `from_wgs84` and the raster's north-up geotransform, and whether its
/// four pixels are all valid (`valid(column, row)`).
fn pixel_positions(path: &Path, lattice: &GeoLattice) -> Vec<(f64, f64)> {
    let info = open_info(path, 1).expect("info");
    let gt = info.geo_transform.expect("geotransform");
    assert!(gt[2] == 0.0 && gt[4] == 0.0);
    let mut points: Vec<[f64; 3]> = (0..lattice.height)
        .flat_map(|j| (0..lattice.width).map(move |i| [lattice.lon(i), lattice.lat(j), 0.0]))
        .collect();
    if !tinsmith_raster::is_wgs84_lon_lat(info.crs_wkt.as_deref().expect("CRS")) {
        tinsmith_raster::from_wgs84(info.crs_wkt.as_deref().expect("CRS"), &mut points)
            .expect("PROJ");
    }
    points
        .iter()
        .map(|p| ((p[0] - gt[0]) / gt[1], (p[1] - gt[3]) / gt[5]))
        .collect()
}

/// Compares the samples of `lattice` with gdalwarp's: equal (to float32 rounding) wherever
/// the four pixels around the point are in the raster and valid (`valid`), nodata for
/// both outside the raster. Returns how many points were compared.
fn check_against_gdalwarp(
    path: &Path,
    lattice: &GeoLattice,
    size: (f64, f64),
    valid: impl Fn(i64, i64) -> bool,
) -> usize {
    let dir = tempfile::tempdir().expect("tempdir");
    let ours =
        sample_geographic(path, 1, lattice, &VerticalDatum::Ellipsoid, f32::NAN).expect("samples");
    let theirs = gdalwarp_samples(dir.path(), path, lattice);
    let (w, h) = size;
    let mut compared = 0;
    for (k, (c, r)) in pixel_positions(path, lattice).into_iter().enumerate() {
        let (a, b) = (f64::from(ours[k]), theirs[k]);
        if c < -1e-6 || r < -1e-6 || c > w + 1e-6 || r > h + 1e-6 {
            assert!(a.is_nan() && b.is_nan(), "point {k} outside: {a} and {b}");
            continue;
        }
        let (x0, y0) = ((c - 0.5).floor() as i64, (r - 0.5).floor() as i64);
        let four = [(x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)];
        if !four.iter().all(|&(x, y)| valid(x, y)) {
            continue;
        }
        assert!(
            (a - b).abs() <= 1e-3 + 1e-6 * b.abs(),
            "{}: point {k} at pixel ({c}, {r}): {a}, gdalwarp {b}",
            path.display()
        );
        compared += 1;
    }
    compared
}

#[test]
fn samples_agree_with_gdalwarp_wherever_the_four_pixels_are_valid() {
    // The Albers DEM (no nodata), on a lattice 2.3 times finer than the raster, over all
    // of it and beyond.
    let albers = fixture("../../data/becmodel_dem_bc_albers_50m.tif");
    let mut lattice = lattice_over(&albers, 1.0);
    lattice.step /= 2.3;
    lattice.first_column = (lattice.first_column as f64 * 2.3) as u64;
    lattice.first_row = (lattice.first_row as f64 * 2.3) as u64;
    lattice.width = (f64::from(lattice.width) * 2.3) as u32;
    lattice.height = (f64::from(lattice.height) * 2.3) as u32;
    let inside = |x: i64, y: i64| (0..430).contains(&x) && (0..516).contains(&y);
    let compared = check_against_gdalwarp(&albers, &lattice, (430.0, 516.0), inside);
    assert!(compared > 500_000, "{compared} points compared");

    // A 0..360 raster with a nodata hole, across 180° in its own frame (GDAL warps the
    // part east of 180° only when the lattice asks for it there).
    let dir = tempfile::tempdir().expect("tempdir");
    let [east, _, _] = global_rasters(dir.path());
    let lattice = GeoLattice {
        latitudes: tinsmith_raster::Latitudes::Uniform,
        west: 100.0,
        south: -80.0,
        step: 0.7,
        first_column: 0,
        first_row: 0,
        width: 229,
        height: 229,
    };
    let valid = |x: i64, y: i64| {
        (0..72).contains(&x)
            && (0..36).contains(&y)
            && global_value(x as usize, y as usize) != -9999.0
    };
    let compared = check_against_gdalwarp(&east, &lattice, (72.0, 36.0), valid);
    assert!(compared > 40_000, "{compared} points compared");
}

#[test]
fn web_mercator_lattices_are_even_in_latitude_inside_each_tile() {
    use tinsmith_raster::{web_mercator_latitude, web_mercator_y, Latitudes};
    // The square world's edges, the equator, and the inverse.
    assert!((web_mercator_latitude(1.0) - 85.051_128_779_806_6).abs() < 1e-12);
    assert_eq!(web_mercator_latitude(0.5), 0.0);
    for y in [0.0, 0.1, 0.37, 0.5, 0.93, 1.0] {
        assert!(
            (web_mercator_y(web_mercator_latitude(y)) - y).abs() < 1e-12,
            "{y}"
        );
    }
    // 4 tiles of 8 rows: rows 8 k are the tiles' edges, the rows between them evenly
    // spaced, and a window's rows are the larger lattice's.
    let lattice = GeoLattice {
        west: -180.0,
        south: -90.0,
        step: 1.0,
        first_column: 0,
        first_row: 0,
        width: 1,
        height: 33,
        latitudes: Latitudes::WebMercatorTiles { cells: 8, tiles: 4 },
    };
    for t in 0..4u32 {
        let (south, north) = (
            web_mercator_latitude(f64::from(t) / 4.0),
            web_mercator_latitude(f64::from(t + 1) / 4.0),
        );
        assert_eq!(lattice.lat(8 * t), south);
        for j in 1..8 {
            let want = south + (north - south) * f64::from(j) / 8.0;
            assert!((lattice.lat(8 * t + j) - want).abs() < 1e-12);
        }
    }
    assert_eq!(lattice.lat(32), web_mercator_latitude(1.0));
    let window = GeoLattice {
        first_row: 13,
        ..lattice
    };
    assert_eq!(window.lat(2), lattice.lat(15));
}
