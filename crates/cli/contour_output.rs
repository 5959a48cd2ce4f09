//! Writing contour lines as GeoJSON or FlatGeobuf: one LineString feature per line with an
//! `id` (the line's position in tinsmith's deterministic order) and its `elev`.
//!
//! Kept in this one module so it can be swapped for the exporters' line-feature writer
//! (tinsmith-export) when that lands.
//!
//! - **GeoJSON** (`.geojson`, `.json`): a FeatureCollection of 2D LineStrings, written in
//!   the lines' order, coordinates in the raster's CRS. RFC 7946 allows only WGS 84
//!   longitude/latitude; like `gdal_contour`, we write the raster's own coordinates
//!   instead and name the CRS in the 2008 GeoJSON `"crs"` member (an OGC URN for an EPSG
//!   code, `OGC:1.3:CRS84` for EPSG:4326, whose coordinates we write as longitude,
//!   latitude), which GDAL/QGIS read. A CRS without an EPSG code is named by its WKT (GDAL
//!   reads that too). No CRS member when the raster has none or `--pixel-coords` is given.
//! - **FlatGeobuf** (`.fgb`): LineString, the CRS as EPSG code and WKT, columns `id` (Long)
//!   and `elev` (Double; GDAL 3.6 reads unsigned 64-bit columns as Real). The spatial
//!   index reorders features (Hilbert sort), so `id` keeps tinsmith's order.
//!
//! Both are written to a temporary file in the target's directory and renamed into place.

use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{bail, Context, Result};
use flatgeobuf::{FgbCrs, FgbWriter, FgbWriterOptions, GeometryType};
use geozero::{ColumnValue, FeatureProcessor, GeomProcessor, PropertyProcessor};

/// The output format, from the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContourFormat {
    /// `.geojson` or `.json`.
    GeoJson,
    /// `.fgb`.
    FlatGeobuf,
}

impl ContourFormat {
    /// The format for `path`'s extension; fails naming the file otherwise.
    pub fn from_path(path: &Path) -> Result<ContourFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("geojson" | "json") => Ok(ContourFormat::GeoJson),
            Some("fgb") => Ok(ContourFormat::FlatGeobuf),
            _ => bail!(
                "{}: unknown contour output format (use .geojson, .json or .fgb)",
                path.display()
            ),
        }
    }
}

/// One contour line in output coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ContourLine {
    /// The level.
    pub elev: f64,
    /// The points; a closed line repeats its first point at the end.
    pub points: Vec<[f64; 2]>,
}

/// The CRS to record.
#[derive(Debug, Clone, Copy, Default)]
pub struct Crs<'a> {
    /// EPSG code, when known.
    pub epsg: Option<u32>,
    /// WKT, when known.
    pub wkt: Option<&'a str>,
}

/// Writes `lines` to `path` atomically: `path` is either untouched or complete.
pub fn write_contours(
    path: &Path,
    format: ContourFormat,
    lines: &[ContourLine],
    crs: Crs<'_>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let tmp = tempfile::NamedTempFile::new_in(dir).with_context(|| {
        format!(
            "{}: cannot create a file in {}",
            path.display(),
            dir.display()
        )
    })?;
    let mut out = BufWriter::new(tmp);
    match format {
        ContourFormat::GeoJson => write_geojson(&mut out, lines, crs),
        ContourFormat::FlatGeobuf => write_fgb(&mut out, lines, crs),
    }
    .and_then(|()| out.flush().map_err(anyhow::Error::from))
    .with_context(|| format!("{}: write failed", path.display()))?;
    let tmp = out
        .into_inner()
        .map_err(|e| e.into_error())
        .with_context(|| format!("{}: write failed", path.display()))?;
    tmp.persist(path)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

/// The GeoJSON 2008 `"crs"` name for `crs`, if any.
fn geojson_crs_name(crs: Crs<'_>) -> Option<String> {
    match (crs.epsg, crs.wkt) {
        (Some(4326), _) => Some("urn:ogc:def:crs:OGC:1.3:CRS84".to_owned()),
        (Some(code), _) => Some(format!("urn:ogc:def:crs:EPSG::{code}")),
        (None, Some(wkt)) => Some(wkt.to_owned()),
        (None, None) => None,
    }
}

fn write_geojson(out: &mut impl Write, lines: &[ContourLine], crs: Crs<'_>) -> Result<()> {
    out.write_all(b"{\"type\":\"FeatureCollection\",\"name\":\"contour\",")?;
    if let Some(name) = geojson_crs_name(crs) {
        let member = serde_json::json!({"type": "name", "properties": {"name": name}});
        write!(out, "\"crs\":{member},")?;
    }
    out.write_all(b"\"features\":[")?;
    for (id, line) in lines.iter().enumerate() {
        if id > 0 {
            out.write_all(b",")?;
        }
        write!(
            out,
            "\n{{\"type\":\"Feature\",\"properties\":{{\"id\":{id},\"elev\":"
        )?;
        serde_json::to_writer(&mut *out, &line.elev)?;
        out.write_all(b"},\"geometry\":{\"type\":\"LineString\",\"coordinates\":")?;
        serde_json::to_writer(&mut *out, &line.points)?;
        out.write_all(b"}}")?;
    }
    out.write_all(b"\n]}\n")?;
    Ok(())
}

fn write_fgb(out: &mut impl Write, lines: &[ContourLine], crs: Crs<'_>) -> Result<()> {
    let options = FgbWriterOptions {
        write_index: true,
        detect_type: false,
        promote_to_multi: false,
        crs: FgbCrs {
            org: crs.epsg.map(|_| "EPSG"),
            code: crs.epsg.map_or(0, |c| c as i32),
            wkt: crs.wkt,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut fgb = FgbWriter::create_with_options("contour", GeometryType::LineString, options)?;
    fgb.add_column("id", flatgeobuf::ColumnType::Long, |_, c| {
        c.nullable = false
    });
    fgb.add_column("elev", flatgeobuf::ColumnType::Double, |_, c| {
        c.nullable = false
    });
    for (id, line) in lines.iter().enumerate() {
        let idx = id as u64;
        fgb.feature_begin(idx)?;
        fgb.properties_begin()?;
        fgb.property(0, "id", &ColumnValue::Long(id as i64))?;
        fgb.property(1, "elev", &ColumnValue::Double(line.elev))?;
        fgb.properties_end()?;
        fgb.geometry_begin()?;
        fgb.linestring_begin(true, line.points.len(), 0)?;
        for (i, p) in line.points.iter().enumerate() {
            fgb.xy(p[0], p[1], i)?;
        }
        fgb.linestring_end(true, 0)?;
        fgb.geometry_end()?;
        fgb.feature_end(idx)?;
    }
    fgb.write(out)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_from_extensions() {
        for (p, f) in [
            ("a.geojson", ContourFormat::GeoJson),
            ("a.JSON", ContourFormat::GeoJson),
            ("dir/a.fgb", ContourFormat::FlatGeobuf),
        ] {
            assert_eq!(ContourFormat::from_path(Path::new(p)).unwrap(), f);
        }
        assert!(ContourFormat::from_path(Path::new("a.shp")).is_err());
        assert!(ContourFormat::from_path(Path::new("a")).is_err());
    }

    #[test]
    fn geojson_is_valid_json_with_crs() {
        let lines = [
            ContourLine {
                elev: 100.0,
                points: vec![[0.0, 0.0], [1.5, 2.0]],
            },
            ContourLine {
                elev: 100.5,
                points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
            },
        ];
        let mut buf = Vec::new();
        let crs = Crs {
            epsg: Some(3005),
            wkt: None,
        };
        write_geojson(&mut buf, &lines, crs).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&buf).unwrap();
        assert_eq!(v["crs"]["properties"]["name"], "urn:ogc:def:crs:EPSG::3005");
        let f = v["features"].as_array().unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[1]["properties"]["elev"], 100.5);
        assert_eq!(f[1]["properties"]["id"], 1);
        assert_eq!(f[0]["geometry"]["coordinates"][1][0], 1.5);
        let mut empty = Vec::new();
        write_geojson(&mut empty, &[], Crs::default()).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&empty).unwrap();
        assert!(v.get("crs").is_none());
        assert_eq!(v["features"].as_array().unwrap().len(), 0);
    }
}
