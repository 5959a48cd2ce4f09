//! Arbitrary bytes as a raster file in GDAL's memory file system, read by
//! `tinsmith_raster::read_samples` and `open_info`: an error naming the file, or samples
//! that are finite or NaN (nodata) with statistics that match them; never a panic.
//!
//! Drivers that fetch other resources (VRT, web services) are skipped, and rasters of more
//! than 2^20 samples are left alone, so that each input stays fast and small in memory.
#![no_main]

use std::path::Path;
use std::sync::Once;

use gdal::Dataset;
use libfuzzer_sys::fuzz_target;

/// The in-memory file the input is written to.
const PATH: &str = "/vsimem/fuzz/input";
/// The most samples a raster may have to be read.
const MAX_SAMPLES: usize = 1 << 20;

static SETUP: Once = Once::new();

fuzz_target!(|data: &[u8]| {
    SETUP.call_once(|| {
        for (key, value) in [
            (
                "GDAL_SKIP",
                "VRT WMS WMTS WCS HTTP DAAS EEDA EEDAI PLMOSAIC OGCAPI STACIT STACTA",
            ),
            ("GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR"),
            ("GDAL_HTTP_TIMEOUT", "1"),
        ] {
            gdal::config::set_config_option(key, value).expect("GDAL config");
        }
        tinsmith_raster::silence_gdal_errors();
    });
    // GDAL borrows the bytes (given a buffer to own, it would free an empty one's dangling
    // pointer); the file is unlinked when `file` drops.
    let mut bytes = data.to_vec();
    let file = gdal::vsi::create_mem_file_from_ref(PATH, &mut bytes).expect("a memory file");
    let small = Dataset::open(PATH).is_ok_and(|d| {
        let (w, h) = d.raster_size();
        w.saturating_mul(h) <= MAX_SAMPLES && d.raster_count() <= 16
    });
    if small {
        check(Path::new(PATH));
    }
    drop(file);
});

/// Reads band 1 of `path` both ways and checks the answers.
fn check(path: &Path) {
    match tinsmith_raster::read_samples(path, 1) {
        Ok(raster) => {
            let (samples, info) = (&raster.samples, &raster.info);
            assert_eq!(
                (samples.width(), samples.height()),
                (info.width, info.height)
            );
            let values = samples.values();
            assert!(values.iter().all(|v| v.is_finite() || v.is_nan()));
            let valid = values.iter().filter(|v| v.is_finite()).count() as u64;
            assert_eq!(valid, info.valid_samples);
            assert_eq!(valid, samples.valid_count() as u64);
            assert!(valid > 0);
            let (min, max) = (info.min.expect("a min"), info.max.expect("a max"));
            assert!(min <= max, "{min} > {max}");
            assert!(values
                .iter()
                .filter(|v| v.is_finite())
                .all(|&v| min <= v && v <= max));
        }
        Err(error) => assert!(error.to_string().starts_with(PATH), "{error}"),
    }
    match tinsmith_raster::open_info(path, 1) {
        Ok(info) => assert_eq!(
            info.valid_samples + info.nodata_samples,
            u64::from(info.width) * u64::from(info.height)
        ),
        Err(error) => assert!(error.to_string().starts_with(PATH), "{error}"),
    }
}
