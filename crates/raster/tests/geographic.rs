//! Warping a lattice in square blocks gives the whole lattice's samples when the lattice is
//! at least as fine as the input (as a terrain pyramid's finest level is): the warper's
//! transformer is exact and its bilinear kernel reads the same four input samples whatever
//! the block, so the samples agree up to the float32 rounding of the block's origin (a few
//! ulps at most). A 0..360 raster, warped a second time shifted by a full turn, blocks the
//! same way.
//!
//! Why square blocks: GDAL picks its kernel per warp from the ratio of the output's size to
//! the bounding box of the input it reads, and widens it (smoothing) when the box looks
//! larger than the output. Full-width bands of 217 rows of the Albers fixture are off the
//! whole warp by up to 6 m on 264,000 samples that way. The rasters here are small enough
//! for GDAL to warp the whole lattice in one chunk. On large ones GDAL's window heuristic
//! still varies from chunk to chunk and from block to block (docs/results.md, ETOPO5).

use std::path::{Path, PathBuf};

use gdal::raster::{Buffer, RasterCreationOptions};
use gdal::spatial_ref::SpatialRef;
use gdal::DriverManager;
use tinsmith_raster::{geographic_bounds, warp_to_geographic, GeoLattice};

fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// Both nodata, or equal but for the float32 rounding of the position (a band's
/// geotransform origin is rounded differently from the whole lattice's, which can move a
/// bilinear result by an ulp).
fn same(a: f32, b: f32) -> bool {
    if a.is_nan() || b.is_nan() {
        return a.is_nan() && b.is_nan();
    }
    (a - b).abs() <= 4.0 * f32::EPSILON * a.abs().max(b.abs()).max(1.0)
}

/// Warps the raster's lattice at the first terrain level at least as fine as the input,
/// whole and in bands of whole tile rows cut into square blocks, and compares.
fn check(path: &Path) {
    let bounds = geographic_bounds(path, 1).expect("bounds");
    let d = (0..24)
        .map(|l| 180.0 / (217.0 * (1u64 << l) as f64))
        .find(|&d| d <= bounds.resolution)
        .expect("a fine enough level");
    let i0 = ((bounds.west + 180.0) / d).floor();
    let j0 = ((bounds.south + 90.0) / d).floor();
    let width = (((bounds.east + 180.0) / d).ceil() - i0 + 1.0) as u32;
    let height = (((bounds.north + 90.0) / d).ceil() - j0 + 1.0) as u32;
    // Each block's position as the pyramid computes it: from global lattice indices.
    let lattice = |rows: std::ops::Range<u32>, columns: std::ops::Range<u32>| GeoLattice {
        west: -180.0 + (i0 + f64::from(columns.start)) * d,
        south: -90.0 + (j0 + f64::from(rows.start)) * d,
        step: d,
        width: columns.end - columns.start,
        height: rows.end - rows.start,
    };
    let whole = warp_to_geographic(path, 1, &lattice(0..height, 0..width)).expect("whole warp");
    assert!(whole.iter().any(|v| v.is_finite()), "{}", path.display());
    // Bands as the pyramid cuts them (whole tile rows, the first with the halo row), each
    // in square blocks.
    for band_rows in [217, 434] {
        let mut banded = Vec::with_capacity(whole.len());
        let mut start = 0;
        for end in (band_rows + 2..height)
            .step_by(band_rows as usize)
            .chain([height])
        {
            let h = end - start;
            let mut rows = vec![f32::NAN; (width * h) as usize];
            for c0 in (0..width).step_by(h as usize) {
                let w = h.min(width - c0);
                let block =
                    warp_to_geographic(path, 1, &lattice(start..end, c0..c0 + w)).expect("block");
                for (r, row) in block.chunks_exact(w as usize).enumerate() {
                    rows[(r * width as usize + c0 as usize)..][..w as usize].copy_from_slice(row);
                }
            }
            banded.extend(rows);
            start = end;
        }
        for (k, (a, b)) in banded.iter().zip(&whole).enumerate() {
            assert!(
                same(*a, *b),
                "{}: sample {k}: {a} in blocks, {b} whole",
                path.display()
            );
        }
    }
}

#[test]
fn projected_rasters_warp_the_same_in_bands() {
    check(&fixture("tests/fixtures/tintn_valid_raster_3857.tif"));
    check(&fixture("../../data/becmodel_dem_bc_albers_50m.tif"));
}

#[test]
fn a_raster_in_0_to_360_warps_the_same_in_bands() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("wrap.tif");
    {
        let (w, h) = (72usize, 36usize);
        let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
        let mut ds = driver
            .create_with_band_type_with_options::<f32, _>(
                &path,
                w,
                h,
                1,
                &RasterCreationOptions::default(),
            )
            .expect("create");
        ds.set_geo_transform(&[0.0, 5.0, 0.0, 90.0, 0.0, -5.0])
            .expect("geotransform");
        ds.set_spatial_ref(&SpatialRef::from_epsg(4326).expect("EPSG:4326"))
            .expect("CRS");
        let mut band = ds.rasterband(1).expect("band");
        band.set_no_data_value(Some(-9999.0)).expect("nodata");
        let values = (0..w * h)
            .map(|k| {
                let (i, j) = ((k % w) as f32, (k / w) as f32);
                if (i - 50.0).abs() < 3.0 && (j - 20.0).abs() < 2.0 {
                    -9999.0
                } else {
                    100.0 * (i * 0.3).sin() + 7.0 * j
                }
            })
            .collect();
        let mut buffer = Buffer::new((w, h), values);
        band.write((0, 0), (w, h), &mut buffer).expect("write");
    }
    check(&path);
}

/// Writes a 72 x 36 Float32 EPSG:4326 raster of 5° pixels whose west edge is `west`.
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
    let mut buffer = Buffer::new((72, 36), values);
    ds.rasterband(1)
        .expect("band")
        .write((0, 0), (72, 36), &mut buffer)
        .expect("write");
}

#[test]
fn a_global_raster_in_0_to_360_or_minus_360_to_0_warps_as_in_minus_180_to_180() {
    // GDAL's warper saw the 0° meridian of a 0..360 raster as an edge: samples within
    // half a pixel west of it got the edge value, and a coarser lattice's chunks reaching
    // past it were blurred far from it (ETOPO5 at level 4: kilometres off at La Palma).
    let dir = tempfile::tempdir().expect("tempdir");
    let value = |i: usize, j: usize| {
        let lon = (i as f32 + 0.5) * 5.0_f32.to_radians();
        300.0 * (3.0 * lon).sin() + 40.0 * ((i * 7 + j * 13) % 11) as f32 + 3.0 * j as f32
    };
    let (east, west) = (dir.path().join("0_360.tif"), dir.path().join("180.tif"));
    let in_0_360: Vec<f32> = (0..72 * 36).map(|k| value(k % 72, k / 72)).collect();
    let in_180: Vec<f32> = (0..72 * 36)
        .map(|k| value((k % 72 + 36) % 72, k / 72))
        .collect();
    let far_west = dir.path().join("-360_0.tif");
    write_global(&far_west, -360.0, in_0_360.clone());
    write_global(&east, 0.0, in_0_360);
    write_global(&west, -180.0, in_180);
    // Global lattices at least as fine as the raster, as a pyramid's finest level is
    // (1.25°: samples within half a pixel west of 0°). Coarser ones take GDAL's widened
    // kernel, whose width follows each view's own size, so the two frames differ there.
    for step in [1.25, 4.5] {
        let width = (360.0 / step) as u32 + 1;
        let lattice = GeoLattice {
            west: -180.0,
            south: -80.0,
            step,
            width,
            height: (160.0 / step) as u32 + 1,
        };
        let b = warp_to_geographic(&west, 1, &lattice).expect("warp -180..180");
        for source in [&east, &far_west] {
            let a = warp_to_geographic(source, 1, &lattice).expect("warp 0..360");
            // Within half a pixel of ±180° the -180..180 raster has an edge of its own.
            let inner = |k: usize| (-180.0 + (k % width as usize) as f64 * step).abs() < 177.5;
            let differ = (0..a.len())
                .filter(|&k| inner(k) && !same(a[k], b[k]))
                .count();
            let (worst, at) = a
                .iter()
                .zip(&b)
                .enumerate()
                .filter(|&(k, _)| inner(k))
                .map(|(k, (x, y))| ((x - y).abs(), k))
                .fold((0.0f32, 0), |w, d| if d.0 > w.0 { d } else { w });
            assert_eq!(
                differ,
                0,
                "{}, step {step}: {differ} of {} samples differ, by up to {worst} at longitude {}",
                source.display(),
                a.len(),
                -180.0 + (at % width as usize) as f64 * step
            );
        }
    }
}
