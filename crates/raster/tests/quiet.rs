//! `silence_gdal_errors` is process-wide, so it gets its own test binary.

use std::fs;

use tinsmith_raster::{open_info, silence_gdal_errors, Error};

#[test]
fn silenced_errors_are_still_reported_in_the_returned_error() {
    silence_gdal_errors();
    silence_gdal_errors(); // twice is harmless
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("notes.txt");
    fs::write(&path, "not a raster\n").expect("write");
    let err = open_info(&path, 1).expect_err("a text file is not a raster");
    assert!(matches!(err, Error::NotARaster { .. }), "{err:?}");
    assert_eq!(
        err.to_string(),
        format!(
            "{}: not a raster GDAL can read (not recognized as a supported file format)",
            path.display()
        )
    );
    // And valid files still read.
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/landlab_hugo_site.asc"
    );
    assert_eq!(
        open_info(fixture.as_ref(), 1)
            .expect("fixture")
            .nodata_samples,
        2028
    );
}
