//! Reading real and generated rasters through GDAL: sizes, nodata counts, ranges,
//! geotransforms, CRS, band selection and every error message.
//!
//! Expected numbers for the committed fixtures come from `tests/fixtures/README.md` (computed
//! with other tools, not with this crate). Generated rasters are written with GDAL's GTiff,
//! PNG and VRT drivers into a temporary directory; their expected counts follow from how
//! they were built.

use std::fs;
use std::path::{Path, PathBuf};

use gdal::raster::{Buffer, GdalType, RasterCreationOptions};
use gdal::{Dataset, DriverManager};
use tinsmith_raster::{open_info, read_samples, Error, RasterInfo};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// The Float32 nearest to a decimal number written in a file, as f64.
fn f32_text(decimal: &str) -> f64 {
    decimal.parse::<f32>().expect("a number") as f64
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temporary directory")
}

/// What to put into a generated single- or multi-band raster.
struct Spec<'a, T> {
    width: usize,
    height: usize,
    bands: Vec<Vec<T>>,
    nodata: Option<f64>,
    geo_transform: Option<[f64; 6]>,
    wkt: Option<&'a str>,
    options: &'a [(&'a str, &'a str)],
}

impl<T: GdalType + Copy> Spec<'_, T> {
    fn new(width: usize, height: usize, values: Vec<T>) -> Self {
        Spec {
            width,
            height,
            bands: vec![values],
            nodata: None,
            geo_transform: Some([100.0, 2.0, 0.0, 500.0, 0.0, -2.0]),
            wkt: None,
            options: &[],
        }
    }

    /// Builds the raster with GDAL's MEM driver.
    fn mem(&self) -> Dataset {
        let driver = DriverManager::get_driver_by_name("MEM").expect("MEM driver");
        let mut ds = driver
            .create_with_band_type::<T, _>("", self.width, self.height, self.bands.len())
            .expect("create MEM raster");
        self.fill(&mut ds);
        ds
    }

    fn fill(&self, ds: &mut Dataset) {
        for (i, values) in self.bands.iter().enumerate() {
            let mut band = ds.rasterband(i + 1).expect("band");
            let mut buf = Buffer::new((self.width, self.height), values.clone());
            band.write((0, 0), (self.width, self.height), &mut buf)
                .expect("write band");
            band.set_no_data_value(self.nodata).expect("set nodata");
        }
        if let Some(gt) = self.geo_transform {
            ds.set_geo_transform(&gt).expect("set geotransform");
        }
        if let Some(wkt) = self.wkt {
            ds.set_projection(wkt).expect("set projection");
        }
    }

    /// Writes the raster as a GeoTIFF at `path`.
    fn tif(&self, path: &Path) -> PathBuf {
        let driver = DriverManager::get_driver_by_name("GTiff").expect("GTiff driver");
        let mut options = RasterCreationOptions::new();
        for (k, v) in self.options {
            options.add_name_value(k, v).expect("creation option");
        }
        let mut ds = driver
            .create_with_band_type_with_options::<T, _>(
                path,
                self.width,
                self.height,
                self.bands.len(),
                &options,
            )
            .expect("create GeoTIFF");
        self.fill(&mut ds);
        ds.close().expect("close GeoTIFF");
        path.to_path_buf()
    }

    /// Writes the raster as a PNG at `path` (GDAL's PNG driver only copies).
    fn png(&self, path: &Path) -> PathBuf {
        let driver = DriverManager::get_driver_by_name("PNG").expect("PNG driver");
        let ds = self.mem();
        let out = ds
            .create_copy(&driver, path, &RasterCreationOptions::new())
            .expect("PNG");
        out.close().expect("close PNG");
        path.to_path_buf()
    }
}

fn err_text(result: Result<impl std::fmt::Debug, Error>) -> (Error, String) {
    let err = result.expect_err("an error");
    let text = err.to_string();
    (err, text)
}

fn check_stats(info: &RasterInfo, valid: u64, nodata: u64, min: f64, max: f64) {
    assert_eq!(
        info.valid_samples,
        valid,
        "valid samples of {}",
        info.path.display()
    );
    assert_eq!(
        info.nodata_samples,
        nodata,
        "nodata samples of {}",
        info.path.display()
    );
    assert_eq!(info.min, Some(min), "min of {}", info.path.display());
    assert_eq!(info.max, Some(max), "max of {}", info.path.display());
}

// ---------------------------------------------------------------------------------------
// Committed real fixtures.

#[test]
fn hugo_site_esri_ascii_int_with_minus_9999() {
    let path = fixture("landlab_hugo_site.asc");
    let raster = read_samples(&path, 1).expect("read hugo_site");
    let info = &raster.info;
    assert_eq!(info.driver, "AAIGrid");
    assert_eq!((info.width, info.height), (76, 55));
    assert_eq!((info.band_count, info.band), (1, 1));
    assert_eq!(info.data_type, "Int32");
    assert_eq!(info.nodata, Some(-9999.0));
    // xllcorner = yllcorner = 0, cellsize 10, 55 rows: the top edge is at y = 550.
    assert_eq!(
        info.geo_transform,
        Some([0.0, 10.0, 0.0, 550.0, 0.0, -10.0])
    );
    assert_eq!(info.crs_wkt, None);
    assert_eq!(info.epsg, None);
    check_stats(info, 76 * 55 - 2028, 2028, 1660.0, 1711.0);

    let grid = &raster.samples;
    assert_eq!((grid.width(), grid.height()), (76, 55));
    assert_eq!(grid.valid_count(), 76 * 55 - 2028);
    assert_eq!(grid.values().iter().filter(|v| v.is_nan()).count(), 2028);
    // The first data row of the file is all -9999.
    assert!((0..76).all(|x| grid.get(x, 0).is_none()));

    // open_info reports the same without keeping the samples.
    assert_eq!(&open_info(&path, 1).expect("info"), info);
}

#[test]
fn scan_progress_counts_rows_up_to_the_height() {
    let path = fixture("landlab_hugo_site.asc");
    let mut calls = Vec::new();
    let info = tinsmith_raster::open_info_with_progress(&path, 1, &mut |done, rows| {
        calls.push((done, rows))
    })
    .expect("info");
    assert_eq!(info, open_info(&path, 1).expect("info"));
    assert!(!calls.is_empty());
    assert!(calls.windows(2).all(|w| w[0].0 < w[1].0), "{calls:?}");
    assert_eq!(calls.last(), Some(&(55, 55)));
}

#[test]
fn info_serialises_to_json_with_stable_field_names() {
    let info = open_info(&fixture("landlab_hugo_site.asc"), 1).expect("info");
    let json = serde_json::to_value(&info).expect("json");
    assert_eq!(json["driver"], "AAIGrid");
    assert_eq!(json["width"], 76);
    assert_eq!(json["height"], 55);
    assert_eq!(json["band"], 1);
    assert_eq!(json["band_count"], 1);
    assert_eq!(json["data_type"], "Int32");
    assert_eq!(json["nodata"], -9999.0);
    assert_eq!(json["epsg"], serde_json::Value::Null);
    assert_eq!(json["crs_wkt"], serde_json::Value::Null);
    assert_eq!(
        json["geo_transform"],
        serde_json::json!([0.0, 10.0, 0.0, 550.0, 0.0, -10.0])
    );
    assert_eq!(json["valid_samples"], 2152);
    assert_eq!(json["nodata_samples"], 2028);
    assert_eq!(json["min"], 1660.0);
    assert_eq!(json["max"], 1711.0);
    assert!(json["path"]
        .as_str()
        .is_some_and(|p| p.ends_with("landlab_hugo_site.asc")));
}

#[test]
fn west_bijou_gully_float_esri_ascii_with_zero_nodata() {
    let path = fixture("landlab_west_bijou_gully.asc");
    let raster = read_samples(&path, 1).expect("read west_bijou_gully");
    let info = &raster.info;
    assert_eq!((info.width, info.height), (43, 89));
    assert_eq!(info.data_type, "Float32");
    assert_eq!(info.nodata, Some(0.0));
    assert_eq!(
        info.geo_transform,
        Some([559705.0, 3.0, 0.0, 4380487.0, 0.0, -3.0])
    );
    // Extremes as written in the file, stored as Float32.
    let (min, max) = (
        f32_text("1680.7793918185764142"),
        f32_text("1725.4326307508681566"),
    );
    check_stats(info, 43 * 89 - 2739, 2739, min, max);
    assert!(raster
        .samples
        .values()
        .iter()
        .all(|v| v.is_nan() || *v > 1000.0));
}

#[test]
fn tin_terrain_geotiff_float32_with_flt_max_nodata_and_epsg_3857() {
    let path = fixture("tintn_valid_raster_3857.tif");
    let raster = read_samples(&path, 1).expect("read valid_raster");
    let info = &raster.info;
    assert_eq!(info.driver, "GTiff");
    assert_eq!((info.width, info.height), (100, 80));
    assert_eq!(info.data_type, "Float32");
    assert_eq!(info.nodata, Some(f32::MIN as f64)); // -3.4028235e38 = -FLT_MAX
    assert_eq!(info.epsg, Some(3857));
    assert!(info
        .crs_wkt
        .as_deref()
        .is_some_and(|w| w.contains("Pseudo-Mercator")));
    let gt = info.geo_transform.expect("geotransform");
    assert!((gt[0] - -13_636_677.018_108_18).abs() < 1e-6);
    assert!((gt[1] - 3.916942413030081).abs() < 1e-12);
    assert!((gt[5] + 3.916942413030081).abs() < 1e-12);
    assert_eq!(info.valid_samples, 8000 - 970);
    assert_eq!(info.nodata_samples, 970);
    // gdal_translate -of XYZ with 10 decimals, rounded to the band's Float32.
    assert_eq!(info.min, Some(f32_text("26.5792274475")));
    assert_eq!(info.max, Some(f32_text("44.0725631714")));
    assert_eq!(raster.samples.valid_count(), 8000 - 970);
}

#[test]
fn real_fixture_other_band_is_out_of_range() {
    let path = fixture("tintn_valid_raster_3857.tif");
    let (err, text) = err_text(open_info(&path, 2));
    assert!(
        matches!(
            err,
            Error::BandOutOfRange {
                band: 2,
                count: 1,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(
        text.ends_with("band 2 out of range, the raster has 1 band(s)"),
        "{text}"
    );
}

// ---------------------------------------------------------------------------------------
// Generated rasters: each numeric type and nodata convention.

#[test]
fn int16_with_minus_32768_nodata() {
    let dir = tempdir();
    let mut values: Vec<i16> = (0..60).map(|i| i * 10 - 200).collect();
    for i in [0, 7, 59] {
        values[i] = i16::MIN;
    }
    let spec = Spec {
        nodata: Some(-32768.0),
        ..Spec::new(10, 6, values)
    };
    let path = spec.tif(&dir.path().join("i16.tif"));
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.data_type, "Int16");
    assert_eq!(raster.info.nodata, Some(-32768.0));
    check_stats(&raster.info, 57, 3, -190.0, 380.0);
    assert_eq!(raster.samples.get(1, 0), Some(-190.0));
    assert_eq!(raster.samples.get(7, 0), None);
    assert_eq!(raster.samples.get(9, 5), None);
    assert_eq!(raster.samples.get(8, 5), Some(380.0));
}

#[test]
fn float32_with_minus_3_4e38_declared_as_f64_like_vinschgau() {
    // vinschgau's GDAL_NODATA tag says -3.4e38 (an f64 that no f32 equals); its pixels hold
    // the nearest f32. Rebuilt here as a Float32 GeoTIFF under a VRT declaring -3.4e38.
    let dir = tempdir();
    let nd = -3.4e38_f32;
    assert_ne!(nd as f64, -3.4e38, "the trap this test is about");
    let mut values: Vec<f32> = (0..4).map(|i| 388.0 + i as f32 * 72.5).collect();
    values[1] = nd;
    let src = Spec::new(2, 2, values).tif(&dir.path().join("f32.tif"));
    let path = dir.path().join("f32.vrt");
    fs::write(
        &path,
        vrt(&src, "Float32", "", "<NoDataValue>-3.4e38</NoDataValue>"),
    )
    .expect("vrt");
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.nodata, Some(-3.4e38));
    check_stats(&info, 3, 1, 388.0, 388.0 + 3.0 * 72.5);

    // An ESRI ASCII grid declaring -3.4e38: GDAL reads it as Float32 (and rounds the
    // declared value to f32 itself).
    let path = dir.path().join("f32.asc");
    let text = "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -3.4e38\n\
                388.5 -3.4e38 400\n-3.4e38 500.25 3863\n";
    fs::write(&path, text).expect("write asc");
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.data_type, "Float32");
    assert_eq!(raster.info.nodata.map(|v| v as f32), Some(nd));
    check_stats(&raster.info, 4, 2, 388.5, 3863.0);
    assert_eq!(raster.samples.valid_count(), 4);

    // GDAL's GTiff driver itself stores a Float32 band's nodata rounded to f32: also matched.
    let mut values: Vec<f32> = (0..48).map(|i| 388.0 + i as f32 * 72.5).collect();
    for i in [3, 4, 5, 40] {
        values[i] = nd;
    }
    let spec = Spec {
        nodata: Some(-3.4e38),
        ..Spec::new(8, 6, values)
    };
    let path = spec.tif(&dir.path().join("f32_direct.tif"));
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.nodata.map(|v| v as f32), Some(nd));
    check_stats(&info, 44, 4, 388.0, 388.0 + 47.0 * 72.5);
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.samples.valid_count(), 44);
    assert_eq!(raster.info, info);
}

#[test]
fn float32_huge_negatives_are_nodata_as_gdal_counts_them() {
    // gdalinfo -stats (GDAL 3.6) on this raster: 50 % valid, -3.3e38 is nodata too (GDAL's
    // f32 comparison overflows that far out); -1e30 is a (strange) valid height.
    let dir = tempdir();
    let values = vec![1.0_f32, -3.4e38, -3.3e38, 2.0];
    let spec = Spec {
        nodata: Some(-3.4e38),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("f32b.tif"));
    let info = open_info(&path, 1).expect("info");
    check_stats(&info, 2, 2, 1.0, 2.0);
    let values = vec![1.0_f32, -3.4e38, -1e30, 2.0];
    let spec = Spec {
        nodata: Some(-3.4e38),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("f32c.tif"));
    let info = open_info(&path, 1).expect("info");
    check_stats(&info, 3, 1, -1e30_f32 as f64, 2.0);
}

#[test]
fn uint16_and_byte_with_and_without_nodata() {
    let dir = tempdir();
    let values: Vec<u16> = (0..30).map(|i| 1000 + i * 1000).collect(); // up to 30000
    let spec = Spec {
        nodata: Some(1000.0),
        ..Spec::new(5, 6, values)
    };
    let path = spec.tif(&dir.path().join("u16.tif"));
    let info = open_info(&path, 1).expect("u16");
    assert_eq!(info.data_type, "UInt16");
    check_stats(&info, 29, 1, 2000.0, 30000.0);

    let values: Vec<u8> = (0..=255).collect();
    let path = Spec::new(16, 16, values).tif(&dir.path().join("u8.tif"));
    let info = open_info(&path, 1).expect("u8");
    assert_eq!(info.data_type, "Byte");
    assert_eq!(info.nodata, None);
    check_stats(&info, 256, 0, 0.0, 255.0);

    // A nodata value a Byte band cannot hold matches nothing.
    let values: Vec<u8> = vec![0, 1, 2, 255];
    let spec = Spec {
        nodata: Some(-9999.0),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("u8nd.tif"));
    check_stats(&open_info(&path, 1).expect("u8nd"), 4, 0, 0.0, 255.0);
}

#[test]
fn uint32_and_int32_extremes() {
    let dir = tempdir();
    let values = vec![0_u32, u32::MAX, 7, 8];
    let spec = Spec {
        nodata: Some(7.0),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("u32.tif"));
    let info = open_info(&path, 1).expect("u32");
    assert_eq!(info.data_type, "UInt32");
    check_stats(&info, 3, 1, 0.0, u32::MAX as f64);

    let values = vec![i32::MIN, i32::MAX, -9999, 5];
    let spec = Spec {
        nodata: Some(-9999.0),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("i32.tif"));
    let info = open_info(&path, 1).expect("i32");
    assert_eq!(info.data_type, "Int32");
    check_stats(&info, 3, 1, i32::MIN as f64, i32::MAX as f64);
}

#[test]
fn signed_byte_reads_negative_heights() {
    // Int8: GDAL < 3.7 calls it Byte with PIXELTYPE=SIGNEDBYTE, GDAL >= 3.7 calls it Int8.
    let dir = tempdir();
    let values: Vec<u8> = vec![0x80, 0xFF, 0x00, 0x7F, 0x05, 0x80]; // -128 -1 0 127 5 -128
    let spec = Spec {
        nodata: Some(-128.0),
        options: &[("PIXELTYPE", "SIGNEDBYTE")],
        ..Spec::new(3, 2, values)
    };
    let path = spec.tif(&dir.path().join("i8.tif"));
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.data_type, "Int8");
    check_stats(&raster.info, 4, 2, -1.0, 127.0);
    assert_eq!(raster.samples.get(1, 0), Some(-1.0));
}

#[test]
fn float64_with_nan_and_no_declared_nodata() {
    let dir = tempdir();
    let mut values: Vec<f64> = (0..20).map(|i| i as f64 * 0.25 - 1.0).collect();
    values[2] = f64::NAN;
    values[3] = f64::INFINITY;
    values[19] = f64::NAN;
    let path = Spec::new(5, 4, values).tif(&dir.path().join("f64.tif"));
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.data_type, "Float64");
    assert_eq!(raster.info.nodata, None);
    check_stats(&raster.info, 17, 3, -1.0, 3.5);
    assert!(
        raster.samples.values()[3].is_nan(),
        "infinity becomes NaN in the grid"
    );
}

#[test]
fn float64_with_minus_9999_like_codem() {
    let dir = tempdir();
    // As GDAL's nodata mask: -9999.000001 is within its tolerance of -9999 (two f32
    // epsilons of the sum, 0.0048 here), -9998.99 is not.
    let values = vec![-9999.0, 225.75, -9999.0, 290.5, -9999.000001, -9998.99];
    let spec = Spec {
        nodata: Some(-9999.0),
        ..Spec::new(3, 2, values)
    };
    let path = spec.tif(&dir.path().join("f64nd.tif"));
    check_stats(&open_info(&path, 1).expect("info"), 3, 3, -9998.99, 290.5);
}

#[test]
fn alpha_band_zeros_are_nodata_whatever_its_type() {
    // gdalwarp -dstalpha writes an alpha band of the data's type; GDAL takes only a Byte
    // (or UInt16) alpha as the band's mask, gdalwarp any. Both must leave out the zeros.
    let dir = tempdir();
    let heights = [10, 11, 12, 13, 14, 15];
    let alpha = [255, 0, 255, 255, 0, 255];
    let int16 = Spec {
        bands: vec![heights.to_vec(), alpha.to_vec()],
        options: &[("ALPHA", "YES")],
        ..Spec::new(3, 2, Vec::<i16>::new())
    };
    let byte = Spec {
        bands: vec![
            heights.iter().map(|&h| h as u8).collect(),
            alpha.iter().map(|&a| a as u8).collect(),
        ],
        options: &[("ALPHA", "YES")],
        ..Spec::new(3, 2, Vec::<u8>::new())
    };
    for (path, kind) in [
        (int16.tif(&dir.path().join("i16.tif")), "alpha band 2"),
        (byte.tif(&dir.path().join("u8.tif")), "alpha band"),
    ] {
        let raster = read_samples(&path, 1).expect("read");
        assert_eq!(raster.info.mask.as_deref(), Some(kind), "{path:?}");
        check_stats(&raster.info, 4, 2, 10.0, 15.0);
        assert!(raster.samples.get(1, 0).is_none() && raster.samples.get(1, 1).is_none());
        assert_eq!(raster.samples.get(0, 1), Some(13.0));
        assert_eq!(&open_info(&path, 1).expect("info"), &raster.info);
    }
}

#[test]
fn per_dataset_mask_zeros_are_nodata() {
    let dir = tempdir();
    let path =
        Spec::new(3, 2, vec![1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0]).tif(&dir.path().join("m.tif"));
    {
        let ds = Dataset::open_ex(
            &path,
            gdal::DatasetOptions {
                open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE,
                ..Default::default()
            },
        )
        .expect("open for update");
        let mut band = ds.rasterband(1).expect("band");
        band.create_mask_band(true).expect("mask");
        let mut mask = band.open_mask_band().expect("mask band");
        let mut buf = Buffer::new((3, 2), vec![255u8, 255, 0, 255, 255, 255]);
        mask.write((0, 0), (3, 2), &mut buf).expect("write mask");
    }
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.mask.as_deref(), Some("per-dataset mask"));
    check_stats(&raster.info, 5, 1, 1.0, 6.0);
    assert!(raster.samples.get(2, 0).is_none());
}

#[test]
fn scale_and_offset_give_real_heights() {
    let dir = tempdir();
    let values: Vec<u16> = vec![0, 1000, 2000, 65535];
    let spec = Spec {
        nodata: Some(65535.0),
        ..Spec::new(2, 2, values)
    };
    let path = spec.tif(&dir.path().join("scaled.tif"));
    {
        let ds = Dataset::open_ex(
            &path,
            gdal::DatasetOptions {
                open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE,
                ..Default::default()
            },
        )
        .expect("reopen");
        let mut band = ds.rasterband(1).expect("band");
        band.set_scale(0.5).expect("scale");
        band.set_offset(-100.0).expect("offset");
    }
    let info = open_info(&path, 1).expect("info");
    assert_eq!((info.scale, info.offset), (0.5, -100.0));
    assert_eq!(info.nodata, Some(65535.0), "nodata is reported unscaled");
    check_stats(&info, 3, 1, -100.0, 900.0);
}

#[test]
fn all_nodata_is_an_error_for_read_samples_only() {
    let dir = tempdir();
    let spec = Spec {
        nodata: Some(-9999.0),
        ..Spec::new(3, 3, vec![-9999_i16; 9])
    };
    let path = spec.tif(&dir.path().join("empty_values.tif"));
    let info = open_info(&path, 1).expect("info");
    assert_eq!((info.valid_samples, info.nodata_samples), (0, 9));
    assert_eq!((info.min, info.max), (None, None));

    let (err, text) = err_text(read_samples(&path, 1));
    assert!(matches!(err, Error::AllNodata { band: 1, .. }), "{err:?}");
    assert_eq!(
        text,
        format!(
            "{}: band 1 has no valid sample (all nodata)",
            path.display()
        )
    );
}

#[test]
fn band_selection_reads_the_chosen_band() {
    let dir = tempdir();
    let spec = Spec {
        bands: vec![vec![1_i16, 2, 3, 4], vec![10, 20, -1, 40], vec![7, 7, 7, 7]],
        nodata: Some(-1.0),
        ..Spec::new(2, 2, vec![])
    };
    let path = spec.tif(&dir.path().join("three.tif"));
    let second = read_samples(&path, 2).expect("band 2");
    assert_eq!((second.info.band, second.info.band_count), (2, 3));
    check_stats(&second.info, 3, 1, 10.0, 40.0);
    assert_eq!(second.samples.get(1, 1), Some(40.0));
    check_stats(&open_info(&path, 3).expect("band 3"), 4, 0, 7.0, 7.0);

    for band in [0, 4] {
        let (err, text) = err_text(read_samples(&path, band));
        assert!(
            matches!(err, Error::BandOutOfRange { count: 3, .. }),
            "{err:?}"
        );
        assert_eq!(
            text,
            format!(
                "{}: band {band} out of range, the raster has 3 band(s)",
                path.display()
            )
        );
    }
}

#[test]
fn geotransform_present_absent_and_rotated() {
    let dir = tempdir();
    let spec = Spec {
        geo_transform: None,
        ..Spec::new(2, 2, vec![1.0_f32, 2.0, 3.0, 4.0])
    };
    let path = spec.tif(&dir.path().join("no_gt.tif"));
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.geo_transform, None);
    assert_eq!(info.transform(), None);

    // An explicit identity is a geotransform like any other.
    let identity = [0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let spec = Spec {
        geo_transform: Some(identity),
        ..Spec::new(2, 2, vec![1.0_f32; 4])
    };
    let path = spec.tif(&dir.path().join("identity_gt.tif"));
    assert_eq!(
        open_info(&path, 1).expect("info").geo_transform,
        Some(identity)
    );

    let rotated = [1000.0, 0.5, 0.25, 2000.0, 0.125, -0.5];
    let spec = Spec {
        geo_transform: Some(rotated),
        ..Spec::new(2, 2, vec![1.0_f32; 4])
    };
    let path = spec.tif(&dir.path().join("rotated_gt.tif"));
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.geo_transform, Some(rotated));
    assert_eq!(
        info.transform(),
        Some(tinsmith_georef::GeoTransform(rotated))
    );
}

#[test]
fn crs_epsg_and_compound_unknown() {
    let dir = tempdir();
    let utm = gdal::spatial_ref::SpatialRef::from_epsg(32632).expect("EPSG:32632");
    let wkt = utm.to_wkt().expect("wkt");
    let spec = Spec {
        wkt: Some(&wkt),
        ..Spec::new(2, 2, vec![1.0_f32; 4])
    };
    let path = spec.tif(&dir.path().join("utm.tif"));
    let info = open_info(&path, 1).expect("info");
    assert_eq!(info.epsg, Some(32632));
    assert!(info
        .crs_wkt
        .as_deref()
        .is_some_and(|w| w.contains("UTM zone 32N")));

    // The CODEM files' CRS: a compound CRS named "unknown", with no EPSG code as a whole.
    let path = dir.path().join("compound.vrt");
    let src = Spec::new(2, 2, vec![1.0_f64; 4]).tif(&dir.path().join("compound_src.tif"));
    fs::write(&path, vrt(&src, "Float64", COMPOUND_UNKNOWN, "")).expect("write vrt");
    let info = open_info(&path, 1).expect("compound CRS must not fail");
    assert_eq!(info.driver, "VRT");
    assert_eq!(info.epsg, None);
    assert!(info
        .crs_wkt
        .as_deref()
        .is_some_and(|w| w.starts_with("COMPD_CS[\"unknown\"")));
}

const COMPOUND_UNKNOWN: &str = r#"COMPD_CS["unknown",PROJCS["WGS 84 / UTM zone 16N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563,AUTHORITY["EPSG","7030"]],AUTHORITY["EPSG","6326"]],PRIMEM["Greenwich",0,AUTHORITY["EPSG","8901"]],UNIT["degree",0.0174532925199433,AUTHORITY["EPSG","9122"]],AUTHORITY["EPSG","4326"]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",-87],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1,AUTHORITY["EPSG","9001"]],AXIS["Easting",EAST],AXIS["Northing",NORTH],AUTHORITY["EPSG","32616"]],VERT_CS["unknown",VERT_DATUM["unknown",2005],UNIT["metre",1,AUTHORITY["EPSG","9001"]],AXIS["Up",UP]]]"#;

/// A one-band VRT over band 1 of `source`, with the given data type, SRS and extra band XML.
fn vrt(source: &Path, data_type: &str, srs: &str, band_extra: &str) -> String {
    let srs = srs
        .replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;");
    format!(
        r#"<VRTDataset rasterXSize="2" rasterYSize="2">
  <SRS>{srs}</SRS>
  <GeoTransform>0, 1, 0, 2, 0, -1</GeoTransform>
  <VRTRasterBand dataType="{data_type}" band="1">{band_extra}
    <SimpleSource>
      <SourceFilename relativeToVRT="0">{}</SourceFilename>
      <SourceBand>1</SourceBand>
    </SimpleSource>
  </VRTRasterBand>
</VRTDataset>
"#,
        source.display()
    )
}

#[test]
fn png_8_and_16_bit_greyscale_are_rasters() {
    let dir = tempdir();
    let values: Vec<u8> = (0..64).map(|i| (i * 4) as u8).collect();
    let spec = Spec {
        geo_transform: None,
        ..Spec::new(8, 8, values)
    };
    let path = spec.png(&dir.path().join("grey8.png"));
    let raster = read_samples(&path, 1).expect("8-bit PNG");
    assert_eq!(raster.info.driver, "PNG");
    assert_eq!(raster.info.data_type, "Byte");
    assert_eq!(
        raster.info.geo_transform, None,
        "a PNG without world file has none"
    );
    assert_eq!(raster.info.crs_wkt, None);
    check_stats(&raster.info, 64, 0, 0.0, 252.0);

    let values: Vec<u16> = (0..64).map(|i| i * 1000 + 3).collect();
    let spec = Spec {
        geo_transform: None,
        ..Spec::new(16, 4, values)
    };
    let path = spec.png(&dir.path().join("grey16.png"));
    let raster = read_samples(&path, 1).expect("16-bit PNG");
    assert_eq!(raster.info.data_type, "UInt16");
    assert_eq!((raster.info.width, raster.info.height), (16, 4));
    check_stats(&raster.info, 64, 0, 3.0, 63003.0);
    assert_eq!(raster.samples.get(15, 3), Some(63003.0));
}

#[test]
fn strips_cover_a_raster_taller_than_one_read() {
    // 1100 x 1000 samples is more than one strip (2^20 samples) of one-row blocks.
    let dir = tempdir();
    let (w, h) = (1100_usize, 1000_usize);
    let values: Vec<i32> = (0..w * h)
        .map(|i| {
            if i % 997 == 0 {
                -9999
            } else {
                (i % 5000) as i32
            }
        })
        .collect();
    let nodata = (0..w * h).filter(|i| i % 997 == 0).count() as u64;
    let spec = Spec {
        nodata: Some(-9999.0),
        ..Spec::new(w, h, values.clone())
    };
    let path = spec.tif(&dir.path().join("big.tif"));
    let raster = read_samples(&path, 1).expect("read");
    check_stats(&raster.info, (w * h) as u64 - nodata, nodata, 0.0, 4999.0);
    let last = (w * h - 1) as f64 % 5000.0;
    assert_eq!(raster.samples.get(w as u32 - 1, h as u32 - 1), Some(last));
    assert_eq!(raster.samples.get(0, 0), None);
    assert_eq!(raster.samples.get(1, 0), Some(1.0));
}

// ---------------------------------------------------------------------------------------
// Inputs that are not (readable) rasters: each gives a clear `Err`, never a panic.

#[test]
fn missing_file() {
    let dir = tempdir();
    let path = dir.path().join("absent.tif");
    let (err, text) = err_text(read_samples(&path, 1));
    assert!(matches!(err, Error::NotFound { .. }), "{err:?}");
    assert_eq!(text, format!("{}: no such file", path.display()));
    let path = dir.path().join("absent_dir/dem.asc");
    let (err, _) = err_text(open_info(&path, 1));
    assert!(matches!(err, Error::NotFound { .. }), "{err:?}");
}

/// Both entry points fail with `NotARaster`, "{path}: not a raster GDAL can read ({reason})",
/// where the reason starts with `reason_start` and GDAL's error is kept as the source.
fn assert_not_a_raster(path: &Path, reason_start: &str) {
    for result in [
        open_info(path, 1).map(|_| ()),
        read_samples(path, 1).map(|_| ()),
    ] {
        let (err, text) = err_text(result);
        assert!(
            matches!(err, Error::NotARaster { .. }),
            "{}: {err:?}",
            path.display()
        );
        let prefix = format!(
            "{}: not a raster GDAL can read ({reason_start}",
            path.display()
        );
        assert!(text.starts_with(&prefix), "{text}");
        assert!(text.ends_with(')'), "{text}");
        assert!(
            std::error::Error::source(&err).is_some(),
            "GDAL's error is the source"
        );
    }
}

#[test]
fn directory_empty_text_and_garbage_files_are_not_rasters() {
    let dir = tempdir();
    let sub = dir.path().join("a_directory");
    fs::create_dir(&sub).expect("mkdir");
    assert_not_a_raster(
        &sub,
        "a directory: not recognized as a supported file format",
    );

    let empty = dir.path().join("empty.tif");
    fs::write(&empty, b"").expect("write");
    assert_not_a_raster(
        &empty,
        "an empty file: not recognized as a supported file format",
    );

    let text = dir.path().join("notes.txt");
    fs::write(&text, "These are notes, not elevations.\nSecond line.\n").expect("write");
    assert_not_a_raster(&text, "not recognized as a supported file format");

    // A TIFF header pointing at a broken directory: GDAL's TIFF reader says why.
    let garbage = dir.path().join("garbage.tif");
    fs::write(&garbage, b"II*\0\x08\0\0\0garbage garbage garbage").expect("write");
    assert_not_a_raster(&garbage, "TIFFReadDirectory");

    // A vector-only file is not a raster either.
    let geojson = dir.path().join("points.geojson");
    fs::write(&geojson, r#"{"type":"FeatureCollection","features":[]}"#).expect("write");
    assert_not_a_raster(&geojson, "not recognized as a supported file format");
}

#[test]
fn truncated_esri_ascii_fails_cleanly() {
    let dir = tempdir();
    let full = fs::read_to_string(fixture("landlab_hugo_site.asc")).expect("fixture");
    let path = dir.path().join("truncated.asc");
    fs::write(&path, &full[..full.len() / 2]).expect("write");
    // The header is intact, so the file opens; reading runs out of lines.
    let (err, text) = err_text(read_samples(&path, 1));
    assert!(matches!(err, Error::Read { band: 1, .. }), "{err:?}");
    let prefix = format!("{}: reading band 1 failed (", path.display());
    assert!(text.starts_with(&prefix), "{text}");
    assert!(
        text.contains("File short"),
        "GDAL's reason, without the path again: {text}"
    );
    assert_eq!(
        text.matches(&path.display().to_string()).count(),
        1,
        "{text}"
    );
    assert!(matches!(open_info(&path, 1), Err(Error::Read { .. })));
}

#[test]
fn read_failure_names_file_and_band() {
    // A VRT whose source file disappears after the VRT is written: opens, then fails to read.
    let dir = tempdir();
    let src = Spec::new(2, 2, vec![1.0_f32; 4]).tif(&dir.path().join("source.tif"));
    let path = dir.path().join("dangling.vrt");
    fs::write(&path, vrt(&src, "Float32", "", "")).expect("write vrt");
    fs::remove_file(&src).expect("remove source");
    let (err, text) = err_text(read_samples(&path, 1));
    assert!(matches!(err, Error::Read { band: 1, .. }), "{err:?}");
    let prefix = format!("{}: reading band 1 failed (", path.display());
    assert!(text.starts_with(&prefix), "{text}");
    assert!(std::error::Error::source(&err).is_some());
}

#[test]
fn complex_band_is_refused() {
    let dir = tempdir();
    let src = Spec::new(2, 2, vec![1_i16; 4]).tif(&dir.path().join("source.tif"));
    let path = dir.path().join("complex.vrt");
    fs::write(&path, vrt(&src, "CFloat32", "", "")).expect("write vrt");
    let (err, text) = err_text(open_info(&path, 1));
    assert!(
        matches!(err, Error::UnsupportedType { band: 1, .. }),
        "{err:?}"
    );
    assert!(
        text.starts_with(&format!("{}: band 1 ", path.display())),
        "{text}"
    );
    assert!(text.contains("not a real-valued"), "{text}");
}

#[test]
fn vrt_nodata_scale_and_offset_are_honoured() {
    let dir = tempdir();
    let src = Spec::new(2, 2, vec![-5_i16, 10, 20, 30]).tif(&dir.path().join("source.tif"));
    let path = dir.path().join("scaled.vrt");
    let extra = "\n    <NoDataValue>-5</NoDataValue><Offset>1000</Offset><Scale>0.1</Scale>";
    fs::write(&path, vrt(&src, "Int16", "", extra)).expect("write vrt");
    let raster = read_samples(&path, 1).expect("read");
    assert_eq!(raster.info.nodata, Some(-5.0));
    assert_eq!(raster.info.valid_samples, 3);
    let v = raster.samples.get(1, 0).expect("valid");
    assert!((v - 1001.0).abs() < 1e-9, "{v}");
    assert!((raster.info.max.expect("max") - 1003.0).abs() < 1e-9);
}

#[cfg(unix)]
#[test]
fn a_file_name_that_is_not_utf8_is_named_as_the_problem() {
    // GDAL is given names as UTF-8: a Latin-1 name was reported as "No such file".
    use std::os::unix::ffi::OsStrExt;
    let dir = tempdir();
    let name = std::ffi::OsStr::from_bytes(b"h\xf6he.asc");
    let path = dir.path().join(name);
    std::fs::copy(fixture("landlab_hugo_site.asc"), &path).unwrap();
    let (err, text) = err_text(open_info(&path, 1));
    assert!(matches!(err, Error::NameNotUtf8 { .. }), "{err:?}");
    assert!(text.contains("not valid UTF-8"), "{text}");
}
