//! Windowed reads decode exactly as whole-band reads: every window of the committed
//! fixtures equals the same rectangle of `read_samples`'s samples, sample for sample (NaN
//! for nodata), and bad windows are errors naming the file.

use std::path::{Path, PathBuf};

use gdal::raster::{Buffer, RasterCreationOptions};
use gdal::DriverManager;
use tinsmith_raster::{open_info, read_samples, read_window, Error, WindowReader};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// Bit patterns, so that NaN == NaN.
fn bits(values: &[f64]) -> Vec<u64> {
    values
        .iter()
        .map(|v| if v.is_nan() { u64::MAX } else { v.to_bits() })
        .collect()
}

fn crop(values: &[f64], width: u32, x0: u32, y0: u32, w: u32, h: u32) -> Vec<f64> {
    (y0..y0 + h)
        .flat_map(|y| (x0..x0 + w).map(move |x| values[(y * width + x) as usize]))
        .collect()
}

#[test]
fn windows_equal_the_whole_band_read() {
    for name in [
        "landlab_hugo_site.asc",
        "landlab_west_bijou_gully.asc",
        "tintn_valid_raster_3857.tif",
    ] {
        let path = fixture(name);
        let whole = read_samples(&path, 1).expect("read_samples");
        let (width, height) = (whole.samples.width(), whole.samples.height());
        let reader = WindowReader::open(&path, 1).expect("open");
        assert_eq!((reader.width(), reader.height()), (width, height));
        assert_eq!(reader.info().valid_samples, 0, "no statistics on open");
        let windows = [
            (0, 0, width, height),
            (0, 0, 2, 2),
            (width - 2, height - 2, 2, 2),
            (3, 5, 17, 11),
            (width / 2, 0, width - width / 2, height),
            (0, height - 1, width, 1),
        ];
        for (x0, y0, w, h) in windows {
            let grid = reader.read_window(x0, y0, w, h).expect("window");
            assert_eq!((grid.width(), grid.height()), (w, h));
            let expected = crop(whole.samples.values(), width, x0, y0, w, h);
            assert_eq!(
                bits(grid.values()),
                bits(&expected),
                "{name} window {x0},{y0} {w}x{h}"
            );
        }
        let one = read_window(&path, 1, 1, 2, 3, 4).expect("read_window");
        assert_eq!(
            bits(one.values()),
            bits(&crop(whole.samples.values(), width, 1, 2, 3, 4))
        );
    }
}

#[test]
fn max_abs_value_comes_from_the_statistics() {
    let info = open_info(&fixture("tintn_valid_raster_3857.tif"), 1).expect("info");
    let (min, max) = (info.min.expect("min"), info.max.expect("max"));
    assert_eq!(info.max_abs_value(), Some(min.abs().max(max.abs())));
    let reader = WindowReader::open(&fixture("tintn_valid_raster_3857.tif"), 1).expect("open");
    assert_eq!(reader.info().max_abs_value(), None);
}

#[test]
fn negative_heights_count_by_magnitude() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("neg.tif");
    {
        let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
        let ds = driver
            .create_with_band_type_with_options::<f32, _>(
                &path,
                3,
                2,
                1,
                &RasterCreationOptions::default(),
            )
            .expect("create");
        let mut band = ds.rasterband(1).expect("band");
        band.set_no_data_value(Some(-9999.0)).expect("nodata");
        let mut buffer = Buffer::new((3, 2), vec![-9999.0, -120.5, 3.0, 40.0, -9999.0, 7.0]);
        band.write((0, 0), (3, 2), &mut buffer).expect("write");
    }
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.max_abs_value(), Some(120.5));
    let grid = read_window(&path, 1, 0, 0, 2, 2).expect("window");
    assert!(grid.values()[0].is_nan() && grid.values()[3].is_nan());
    assert_eq!((grid.values()[1], grid.values()[2]), (-120.5, 40.0));
}

#[test]
fn windows_outside_the_raster_are_errors_naming_the_file() {
    let path = fixture("landlab_hugo_site.asc");
    let reader = WindowReader::open(&path, 1).expect("open");
    for (x0, y0, w, h) in [
        (0, 0, 77, 1),
        (0, 0, 1, 56),
        (75, 0, 2, 2),
        (0, 54, 1, 2),
        (0, 0, 0, 5),
        (0, 0, 5, 0),
        (u32::MAX, 0, 2, 2),
    ] {
        let err = reader.read_window(x0, y0, w, h).expect_err("out of range");
        assert!(
            matches!(
                err,
                Error::WindowOutOfRange {
                    raster_width: 76,
                    raster_height: 55,
                    ..
                }
            ),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(
            text.starts_with(&format!("{}: window of", path.display())),
            "{text}"
        );
        assert!(text.contains("76x55"), "{text}");
    }
    let err = read_window(Path::new("/no/such/dem.tif"), 1, 0, 0, 1, 1).expect_err("missing");
    assert!(matches!(err, Error::NotFound { .. }), "{err:?}");
    let err = WindowReader::open(&path, 2).expect_err("band 2");
    assert!(matches!(err, Error::BandOutOfRange { .. }), "{err:?}");
}

#[test]
fn a_reader_moves_to_another_thread() {
    let reader = WindowReader::open(&fixture("landlab_hugo_site.asc"), 1).expect("open");
    let grid = std::thread::spawn(move || reader.read_window(0, 0, 4, 4).expect("window"))
        .join()
        .expect("thread");
    assert_eq!(grid.width(), 4);
}

/// A Float32 GeoTIFF of `width` x `height` with nodata -9999 everywhere but `valid`.
fn sparse_raster(
    dir: &Path,
    name: &str,
    (width, height): (usize, usize),
    valid: &[(usize, usize)],
) -> PathBuf {
    let path = dir.join(name);
    let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
    let ds = driver
        .create_with_band_type_with_options::<f32, _>(
            &path,
            width,
            height,
            1,
            &RasterCreationOptions::default(),
        )
        .expect("create");
    let mut band = ds.rasterband(1).expect("band");
    band.set_no_data_value(Some(-9999.0)).expect("nodata");
    let mut values = vec![-9999.0f32; width * height];
    for &(x, y) in valid {
        values[y * width + x] = 1.0;
    }
    let mut buffer = Buffer::new((width, height), values);
    band.write((0, 0), (width, height), &mut buffer)
        .expect("write");
    path
}

#[test]
fn a_valid_cell_is_found_wherever_it_is_and_only_if_there_is_one() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 2^19 columns: bands of two rows, so the block on rows 1 and 2 straddles the first
    // two bands and is only found through the row they share.
    let wide = (1usize << 19, 4);
    let block = [(7, 1), (8, 1), (7, 2), (8, 2)];
    type Samples = Vec<(usize, usize)>;
    let cases: [(&str, (usize, usize), Samples, bool); 6] = [
        // Nodata in the first band of rows (256 of 4096 columns): the coarse look (every
        // 16th sample) lands on the block, before the scan would.
        (
            "far.tif",
            (4096, 1024),
            vec![(712, 712), (713, 712), (712, 713), (713, 713)],
            true,
        ),
        ("straddling.tif", wide, block.to_vec(), true),
        ("empty.tif", wide, vec![], false),
        // Valid samples, but no four of them in a 2x2 block.
        (
            "checker.tif",
            (9, 7),
            (0..63)
                .filter(|i| (i % 9 + i / 9) % 2 == 0)
                .map(|i| (i % 9, i / 9))
                .collect(),
            false,
        ),
        (
            "last.tif",
            (9, 7),
            vec![(7, 5), (8, 5), (7, 6), (8, 6)],
            true,
        ),
        ("row.tif", (9, 1), (0..9).map(|x| (x, 0)).collect(), false),
    ];
    for (name, size, valid, expected) in cases {
        let path = sparse_raster(dir.path(), name, size, &valid);
        let reader = WindowReader::open(&path, 1).expect("open");
        assert_eq!(reader.has_valid_cell().expect("read"), expected, "{name}");
    }
}

/// A Float32 GeoTIFF of `width` x `height` in 16 x 16 tiles, sample (x, y) = x + 1000 y,
/// nodata -9999 on the diagonal.
fn tiled_raster(dir: &Path, (width, height): (usize, usize)) -> PathBuf {
    let path = dir.join("tiled.tif");
    let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff");
    let options = RasterCreationOptions::from_iter(["TILED=YES", "BLOCKXSIZE=16", "BLOCKYSIZE=16"]);
    let ds = driver
        .create_with_band_type_with_options::<f32, _>(&path, width, height, 1, &options)
        .expect("create");
    let mut band = ds.rasterband(1).expect("band");
    band.set_no_data_value(Some(-9999.0)).expect("nodata");
    let values = (0..width * height)
        .map(|k| {
            let (x, y) = (k % width, k / width);
            if x == y {
                -9999.0
            } else {
                (x + 1000 * y) as f32
            }
        })
        .collect();
    let mut buffer = Buffer::new((width, height), values);
    band.write((0, 0), (width, height), &mut buffer)
        .expect("write");
    path
}

#[test]
fn a_lattice_holds_the_samples_the_whole_band_read_has_there() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiled = tiled_raster(dir.path(), (70, 45));
    for path in [tiled, fixture("landlab_hugo_site.asc")] {
        let whole = read_samples(&path, 1).expect("read_samples");
        let (width, height) = (whole.samples.width(), whole.samples.height());
        let values = whole.samples.values();
        let mut reader = WindowReader::open(&path, 1).expect("open");
        let lattices: [(Vec<u32>, Vec<u32>); 4] = [
            ((0..width).collect(), (0..height).collect()),
            (
                (0..width).step_by(7).collect(),
                (3..height).step_by(5).collect(),
            ),
            (vec![width - 1], vec![0, height - 1]),
            (vec![1, 15, 16, 17, width - 2], vec![15, 16, 31, 32]),
        ];
        for (columns, rows) in lattices {
            let got = reader.read_lattice(&columns, &rows).expect("lattice");
            let expected: Vec<f64> = rows
                .iter()
                .flat_map(|&y| {
                    columns
                        .iter()
                        .map(move |&x| values[(y * width + x) as usize])
                })
                .collect();
            assert_eq!(
                bits(&got),
                bits(&expected),
                "{} {columns:?} {rows:?}",
                path.display()
            );
        }
        for (columns, rows) in [
            (vec![2, 2], vec![0]),
            (vec![width], vec![0]),
            (vec![0], vec![3, 1]),
        ] {
            let err = reader.read_lattice(&columns, &rows).unwrap_err();
            assert!(matches!(err, Error::WindowOutOfRange { .. }), "{err}");
        }
    }
}
