//! The line-feature writer, read back by GDAL's `ogrinfo` (Debian gdal-bin, installed by
//! `make deps`): geometry type, feature count, the `id` and `elev` attributes, the CRS and
//! the coordinates.

use std::path::Path;
use std::process::Command;

use tinsmith_formats::{write_lines, CrsRef, LineFormat};

const WKT_3005: &str = "PROJCS[\"NAD83 / BC Albers\",GEOGCS[\"NAD83\",DATUM[\"North_American_Datum_1983\",SPHEROID[\"GRS 1980\",6378137,298.257222101]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Albers_Conic_Equal_Area\"],PARAMETER[\"latitude_of_center\",45],PARAMETER[\"longitude_of_center\",-126],PARAMETER[\"standard_parallel_1\",50],PARAMETER[\"standard_parallel_2\",58.5],PARAMETER[\"false_easting\",1000000],PARAMETER[\"false_northing\",0],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"3005\"]]";

fn ogrinfo(path: &Path) -> String {
    let out = Command::new("ogrinfo")
        .args(["-al", "-q"])
        .arg(path)
        .output()
        .expect("ogrinfo (gdal-bin) must be installed: run `make deps`");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn summary(path: &Path) -> String {
    let out = Command::new("ogrinfo")
        .args(["-so", "-al"])
        .arg(path)
        .output()
        .expect("ogrinfo");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn ogrinfo_reads_3d_lines_with_elev_in_both_formats() -> tinsmith_formats::Result<()> {
    let dir = tempfile::tempdir().expect("temp dir");
    let a: &[[f64; 3]] = &[
        [1_200_000.5, 500_000.25, 250.0],
        [1_200_050.0, 500_010.0, 250.0],
    ];
    let b: &[[f64; 3]] = &[
        [1_200_100.0, 500_100.0, 300.0],
        [1_200_150.0, 500_100.0, 300.0],
        [1_200_150.0, 500_150.0, 300.0],
    ];
    for (format, name) in [
        (LineFormat::GeoJson, "c.geojson"),
        (LineFormat::FlatGeobuf, "c.fgb"),
    ] {
        let path = dir.path().join(name);
        let crs = CrsRef::new(Some(WKT_3005), Some(3005));
        write_lines(&path, format, &[(a, 250.0), (b, 300.0)], crs)?;
        let so = summary(&path);
        assert!(so.contains("Geometry: 3D Line String"), "{name}: {so}");
        assert!(so.contains("Feature Count: 2"), "{name}: {so}");
        assert!(so.contains("ID[\"EPSG\",3005]"), "{name}: {so}");
        assert!(so.contains("elev: Real"), "{name}: {so}");
        assert!(so.contains("id: Integer"), "{name}: {so}");
        let all = ogrinfo(&path);
        assert!(all.contains("elev (Real) = 250"), "{name}: {all}");
        assert!(all.contains("elev (Real) = 300"), "{name}: {all}");
        assert!(
            all.contains("LINESTRING Z (1200000.5 500000.25 250,1200050 500010 250)"),
            "{name}: {all}"
        );
        assert!(
            all.contains("LINESTRING Z (1200100 500100 300,1200150 500100 300,1200150 500150 300)"),
            "{name}: {all}"
        );
    }
    Ok(())
}

#[test]
fn ogrinfo_reads_2d_lines_in_wgs84_geojson() -> tinsmith_formats::Result<()> {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("c.geojson");
    let a: &[[f64; 2]] = &[[-123.5, 49.25], [-123.25, 49.5]];
    write_lines(
        &path,
        LineFormat::GeoJson,
        &[(a, 10.5)],
        CrsRef::new(None, Some(4326)),
    )?;
    let so = summary(&path);
    assert!(so.contains("Geometry: Line String"), "{so}");
    assert!(so.contains("GEOGCRS[\"WGS 84\""), "{so}");
    let all = ogrinfo(&path);
    assert!(
        all.contains("LINESTRING (-123.5 49.25,-123.25 49.5)"),
        "{all}"
    );
    assert!(all.contains("elev (Real) = 10.5"), "{all}");
    Ok(())
}
