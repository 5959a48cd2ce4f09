//! `silence_gdal_errors` is process-wide, so it gets its own test binary.

use std::fs;

use tinsmith_raster::{open_info, silence_gdal_errors, take_gdal_warnings, Error};

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

#[test]
fn warnings_are_held_until_taken_not_printed() {
    silence_gdal_errors();
    // The fixture with its GDALMetadata tag (42112) pointing past the end of the file:
    // GDAL warns that it ignores the tag, and reads the raster.
    let fixture = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/tintn_valid_raster_3857.tif"
    );
    let mut bytes = fs::read(fixture).expect("fixture");
    assert_eq!(
        &bytes[..8],
        b"II*\0\x08\0\0\0",
        "a little-endian TIFF, first IFD at 8"
    );
    let entries = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let at = (0..entries)
        .map(|i| 10 + 12 * i)
        .find(|&at| u16::from_le_bytes([bytes[at], bytes[at + 1]]) == 42112)
        .expect("a GDALMetadata tag");
    bytes[at + 8..at + 12].copy_from_slice(&1_000_000u32.to_le_bytes());
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("bad_tag.tif");
    fs::write(&path, bytes).expect("write");
    open_info(&path, 1).expect("read despite the ignored tag");
    let held = take_gdal_warnings();
    assert!(held.iter().any(|w| w.contains("GDALMetadata")), "{held:?}");
    assert!(take_gdal_warnings().is_empty());
}
