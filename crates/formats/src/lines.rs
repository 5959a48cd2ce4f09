//! Line features (contours, breaklines): GeoJSON or FlatGeobuf `LineString`s with an
//! `elev` attribute, streamed and written atomically.

use std::io::{self, Write};
use std::path::Path;

use flatgeobuf::geozero::{ColumnValue, FeatureProcessor, GeomProcessor, PropertyProcessor};
use flatgeobuf::{ColumnType, FgbWriter, FgbWriterOptions, GeometryType};
use tinsmith_output::write_atomically;

use crate::error::{Error, Result};
use crate::{fgb, geojson};

/// Name of the line-position attribute (`Long` in FlatGeobuf: GDAL reads unsigned 64-bit
/// columns as reals).
const ID: &str = "id";
/// Name of the elevation attribute.
const ELEV: &str = "elev";

/// The vector formats [`write_lines`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum LineFormat {
    /// A GeoJSON `FeatureCollection` of `LineString` features; the CRS is described as for
    /// [`crate::MeshFormat::GeoJson`] (plain RFC 7946 for EPSG 4326, otherwise a `crs`
    /// member and a note).
    GeoJson,
    /// FlatGeobuf `LineString` features with a spatial index and the CRS in the header.
    FlatGeobuf,
}

impl LineFormat {
    /// The extensions [`LineFormat::from_path`] recognises, without the dot, and their
    /// formats.
    const EXTENSIONS: [(&'static str, LineFormat); 3] = [
        ("geojson", LineFormat::GeoJson),
        ("json", LineFormat::GeoJson),
        ("fgb", LineFormat::FlatGeobuf),
    ];

    /// Picks the format from the path's extension, ignoring ASCII case: `.geojson` or
    /// `.json` for GeoJSON, `.fgb` for FlatGeobuf.
    ///
    /// # Errors
    /// [`Error::UnknownLineExtension`], naming the path and the supported extensions, if
    /// the extension is missing, not UTF-8 or not one of these.
    pub fn from_path(path: &Path) -> Result<LineFormat> {
        path.extension()
            .and_then(|extension| extension.to_str())
            .and_then(|extension| {
                Self::EXTENSIONS
                    .into_iter()
                    .find(|(known, _)| known.eq_ignore_ascii_case(extension))
            })
            .map(|(_, format)| format)
            .ok_or_else(|| Error::UnknownLineExtension {
                path: path.to_path_buf(),
            })
    }

    /// `".geojson, .json, .fgb"`, for messages.
    pub(crate) fn supported_extensions() -> String {
        let list: Vec<String> = Self::EXTENSIONS
            .iter()
            .map(|(extension, _)| format!(".{extension}"))
            .collect();
        list.join(", ")
    }
}

/// A point type of a line: 2D `[x, y]` or 3D `[x, y, z]`.
pub trait LinePoint: Copy {
    /// Whether the points carry a height (written as Z).
    const HAS_Z: bool;
    /// The coordinates: 2 or 3 values.
    fn coordinates(&self) -> &[f64];
}

impl LinePoint for [f64; 2] {
    const HAS_Z: bool = false;
    fn coordinates(&self) -> &[f64] {
        self
    }
}

impl LinePoint for [f64; 3] {
    const HAS_Z: bool = true;
    fn coordinates(&self) -> &[f64] {
        self
    }
}

/// The coordinate reference system of features to write.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CrsRef<'a> {
    /// The CRS as WKT.
    pub wkt: Option<&'a str>,
    /// Its EPSG code, when known; `Some(4326)` means longitude, latitude.
    pub epsg: Option<u32>,
}

impl<'a> CrsRef<'a> {
    /// A CRS from its WKT and EPSG code (either may be absent).
    pub fn new(wkt: Option<&'a str>, epsg: Option<u32>) -> CrsRef<'a> {
        CrsRef { wkt, epsg }
    }
}

/// Writes `lines` — each a polyline and its elevation — to `path` as `LineString`
/// features with an `id` (the line's position in `lines`, an integer) and an `elev`
/// (double) attribute, in the given order, atomically.
///
/// With `[f64; 3]` points the features are `LineString Z`; with `[f64; 2]` they are 2D.
/// Coordinates are written as given, GeoJSON's with the shortest decimals that read back
/// to the same `f64`. The CRS is recorded in the file (GeoJSON: as for
/// [`crate::MeshFormat::GeoJson`]; FlatGeobuf: header WKT and EPSG code). Features are
/// streamed to a temporary file and renamed into place. The GeoJSON order is the slice's;
/// FlatGeobuf's spatial index sorts the features along a Hilbert curve, so there `id`
/// gives the slice's order back. The same input gives the same bytes.
///
/// # Errors
/// - [`Error::InvalidLine`] for a line with fewer than two points or a non-finite
///   coordinate or elevation, found before any file is created.
/// - [`Error::MissingDirectory`], [`Error::Io`] as for [`crate::write_mesh`].
///
/// After an error nothing new is left on disk.
///
/// # Example
/// ```
/// use tinsmith_formats::{write_lines, CrsRef, LineFormat};
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let contour: &[[f64; 2]] = &[[500_000.0, 5_000_000.0], [500_050.0, 5_000_020.0]];
/// write_lines(
///     &dir.path().join("contours.geojson"),
///     LineFormat::GeoJson,
///     &[(contour, 250.0)],
///     CrsRef::new(None, Some(32610)),
/// )?;
/// # Ok(())
/// # }
/// ```
pub fn write_lines<P: LinePoint>(
    path: &Path,
    format: LineFormat,
    lines: &[(&[P], f64)],
    crs: CrsRef<'_>,
) -> Result<()> {
    let single: Vec<(&[&[P]], f64)> = lines
        .iter()
        .map(|(points, elev)| (std::slice::from_ref(points), *elev))
        .collect();
    write_multilines(path, format, &single, crs)
}

/// [`write_lines`] for lines of one or more parts (a line cut where it crosses the
/// antimeridian, say): a line of one part is a `LineString` feature, one of several a
/// `MultiLineString` with the parts in the given order. In FlatGeobuf, whose header names
/// one geometry type, every feature is then a `MultiLineString` if any line has several
/// parts. Every part needs at least two points; errors name the line and the part.
pub fn write_multilines<P: LinePoint>(
    path: &Path,
    format: LineFormat,
    lines: &[(&[&[P]], f64)],
    crs: CrsRef<'_>,
) -> Result<()> {
    for (line, (parts, elev)) in lines.iter().enumerate() {
        let invalid = |reason: String| Error::InvalidLine {
            path: path.to_path_buf(),
            line,
            reason,
        };
        if parts.is_empty() {
            return Err(invalid("no part; a line needs at least one".to_owned()));
        }
        if !elev.is_finite() {
            return Err(invalid(format!("non-finite elevation {elev}")));
        }
        for (part, points) in parts.iter().enumerate() {
            let which = if parts.len() > 1 {
                format!("part {part}: ")
            } else {
                String::new()
            };
            if points.len() < 2 {
                return Err(invalid(format!(
                    "{which}{} point(s); a line needs at least 2",
                    points.len()
                )));
            }
            if let Some(k) = points
                .iter()
                .position(|p| !p.coordinates().iter().all(|c| c.is_finite()))
            {
                return Err(invalid(format!(
                    "{which}point {k} has a non-finite coordinate"
                )));
            }
        }
    }
    write_atomically(path, |w| match format {
        LineFormat::GeoJson => write_geojson(w, lines, crs),
        LineFormat::FlatGeobuf => write_fgb(w, lines, crs),
    })
    .map_err(Error::from)
}

fn write_geojson<W: Write, P: LinePoint>(
    mut w: W,
    lines: &[(&[&[P]], f64)],
    crs: CrsRef<'_>,
) -> io::Result<()> {
    geojson::write_collection_start(&mut w, crs.wkt, crs.epsg)?;
    for (i, (parts, elev)) in lines.iter().enumerate() {
        if i > 0 {
            w.write_all(b",\n")?;
        }
        let kind = if parts.len() > 1 {
            "MultiLineString"
        } else {
            "LineString"
        };
        write!(
            w,
            "{{\"type\":\"Feature\",\"properties\":{{\"id\":{i},\"elev\":{elev:?}}},\
             \"geometry\":{{\"type\":\"{kind}\",\"coordinates\":"
        )?;
        if parts.len() > 1 {
            w.write_all(b"[")?;
        }
        for (part, points) in parts.iter().enumerate() {
            if part > 0 {
                w.write_all(b",")?;
            }
            w.write_all(b"[")?;
            for (k, p) in points.iter().enumerate() {
                if k > 0 {
                    w.write_all(b",")?;
                }
                geojson::write_position(&mut w, p.coordinates())?;
            }
            w.write_all(b"]")?;
        }
        if parts.len() > 1 {
            w.write_all(b"]")?;
        }
        w.write_all(b"}}")?;
    }
    w.write_all(b"\n]}\n")
}

fn write_fgb<W: Write, P: LinePoint>(
    w: W,
    lines: &[(&[&[P]], f64)],
    crs: CrsRef<'_>,
) -> io::Result<()> {
    let multi = lines.iter().any(|(parts, _)| parts.len() > 1);
    let options = FgbWriterOptions {
        // GDAL cannot open a file whose header announces an index over no feature.
        write_index: !lines.is_empty(),
        detect_type: false,
        promote_to_multi: false,
        has_z: P::HAS_Z,
        crs: fgb::crs(crs.wkt, crs.epsg),
        ..FgbWriterOptions::default()
    };
    let kind = if multi {
        GeometryType::MultiLineString
    } else {
        GeometryType::LineString
    };
    let mut out = FgbWriter::create_with_options("lines", kind, options).map_err(fgb::io_error)?;
    out.add_column(ID, ColumnType::Long, |_, _| {});
    out.add_column(ELEV, ColumnType::Double, |_, _| {});
    for (i, (parts, elev)) in lines.iter().enumerate() {
        out.property(0, ID, &ColumnValue::Long(i as i64))
            .map_err(fgb::io_error)?;
        out.property(1, ELEV, &ColumnValue::Double(*elev))
            .map_err(fgb::io_error)?;
        if multi {
            out.multilinestring_begin(parts.len(), 0)
                .map_err(fgb::io_error)?;
        }
        for (part, points) in parts.iter().enumerate() {
            out.linestring_begin(!multi, points.len(), part)
                .map_err(fgb::io_error)?;
            for (k, p) in points.iter().enumerate() {
                let c = p.coordinates();
                out.coordinate(c[0], c[1], c.get(2).copied(), None, None, None, k)
                    .map_err(fgb::io_error)?;
            }
            out.linestring_end(!multi, part).map_err(fgb::io_error)?;
        }
        if multi {
            out.multilinestring_end(0).map_err(fgb::io_error)?;
        }
        out.feature_end(i as u64).map_err(fgb::io_error)?;
    }
    out.write(w).map_err(fgb::io_error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flatgeobuf::{FallibleStreamingIterator, FeatureProperties, FgbReader};

    #[test]
    fn geojson_lines_carry_elev_and_order() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("c.geojson");
        let a: &[[f64; 3]] = &[[0.0, 0.0, 5.0], [1.0, 0.5, 5.0]];
        let b: &[[f64; 3]] = &[[2.0, 2.0, 10.0], [3.0, 2.0, 10.0], [3.0, 3.0, 10.0]];
        write_lines(
            &path,
            LineFormat::GeoJson,
            &[(a, 5.0), (b, 10.0)],
            CrsRef::new(None, Some(4326)),
        )?;
        let text = std::fs::read_to_string(&path).expect("read back");
        let value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
        assert!(value.get("crs").is_none());
        assert_eq!(value["features"][1]["properties"]["elev"], 10.0);
        assert_eq!(value["features"][1]["properties"]["id"], 1);
        assert_eq!(
            value["features"][1]["geometry"]["coordinates"][2],
            serde_json::json!([3.0, 3.0, 10.0])
        );
        Ok(())
    }

    #[test]
    fn fgb_lines_read_back_with_flatgeobuf() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("c.fgb");
        let a: &[[f64; 2]] = &[[0.0, 0.0], [1.0, 0.5]];
        let b: &[[f64; 2]] = &[[2.0, 2.0], [3.0, 2.0], [3.0, 3.0]];
        write_lines(
            &path,
            LineFormat::FlatGeobuf,
            &[(a, 5.0), (b, 10.5)],
            CrsRef::new(Some("PROJCS[\"x\"]"), Some(3005)),
        )?;
        let file = std::fs::File::open(&path).expect("open");
        let reader = FgbReader::open(std::io::BufReader::new(file)).expect("fgb");
        assert_eq!(reader.header().geometry_type(), GeometryType::LineString);
        assert_eq!(reader.header().crs().map(|c| c.code()), Some(3005));
        let mut features = reader.select_all_seq().expect("features");
        let mut read = Vec::new();
        while let Some(feature) = features.next().expect("feature") {
            let id = feature.property::<i64>("id").expect("id");
            read.push((id, feature.property::<f64>("elev").expect("elev")));
        }
        read.sort_by_key(|&(id, _)| id);
        assert_eq!(read, vec![(0, 5.0), (1, 10.5)]);
        Ok(())
    }

    #[test]
    fn lines_of_several_parts_are_multilinestrings() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let east: &[[f64; 2]] = &[[179.0, 0.0], [180.0, 0.5]];
        let west: &[[f64; 2]] = &[[-180.0, 0.5], [-179.0, 1.0]];
        let whole: &[[f64; 2]] = &[[10.0, 0.0], [11.0, 0.0]];
        let lines: [(&[&[[f64; 2]]], f64); 2] = [(&[east, west], 5.0), (&[whole], 7.0)];
        let path = dir.path().join("c.geojson");
        write_multilines(
            &path,
            LineFormat::GeoJson,
            &lines,
            CrsRef::new(None, Some(4326)),
        )?;
        let text = std::fs::read_to_string(&path).expect("read back");
        let value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
        let first = &value["features"][0]["geometry"];
        assert_eq!(first["type"], "MultiLineString");
        assert_eq!(
            first["coordinates"],
            serde_json::json!([[[179.0, 0.0], [180.0, 0.5]], [[-180.0, 0.5], [-179.0, 1.0]]])
        );
        assert_eq!(value["features"][1]["geometry"]["type"], "LineString");

        let path = dir.path().join("c.fgb");
        write_multilines(
            &path,
            LineFormat::FlatGeobuf,
            &lines,
            CrsRef::new(None, Some(4326)),
        )?;
        let file = std::fs::File::open(&path).expect("open");
        let reader = FgbReader::open(std::io::BufReader::new(file)).expect("fgb");
        assert_eq!(
            reader.header().geometry_type(),
            GeometryType::MultiLineString
        );
        let mut features = reader.select_all_seq().expect("features");
        let mut parts = Vec::new();
        while let Some(feature) = features.next().expect("feature") {
            let geometry = feature.geometry().expect("geometry");
            let id = feature.property::<i64>("id").expect("id");
            parts.push((id, geometry.ends().map(|e| e.len()).unwrap_or(0)));
        }
        parts.sort();
        // Two parts: one end index between them; one part: no ends array.
        assert_eq!(parts, vec![(0, 2), (1, 0)]);

        let error_of = |lines: &[(&[&[[f64; 2]]], f64)]| {
            write_multilines(&path, LineFormat::GeoJson, lines, CrsRef::default())
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        let error = error_of(&[(&[], 1.0)]);
        assert!(error.contains("line 0: no part"), "{error}");
        let short: &[[f64; 2]] = &[[0.0, 0.0]];
        let error = error_of(&[(&[whole, short], 1.0)]);
        assert!(error.contains("line 0: part 1: 1 point(s)"), "{error}");
        Ok(())
    }

    #[test]
    fn formats_from_extensions() {
        for (path, format) in [
            ("a.geojson", LineFormat::GeoJson),
            ("a.JSON", LineFormat::GeoJson),
            ("dir/a.fgb", LineFormat::FlatGeobuf),
        ] {
            assert_eq!(LineFormat::from_path(Path::new(path)).ok(), Some(format));
        }
        for path in ["a.shp", "a", "a.ply"] {
            let error = LineFormat::from_path(Path::new(path))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(error.starts_with(path), "{error}");
            assert!(error.contains(".geojson, .json, .fgb"), "{error}");
        }
    }

    #[test]
    fn invalid_lines_are_refused_before_any_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("c.geojson");
        let short: &[[f64; 2]] = &[[0.0, 0.0]];
        let nan: &[[f64; 2]] = &[[0.0, 0.0], [f64::NAN, 1.0]];
        let good: &[[f64; 2]] = &[[0.0, 0.0], [1.0, 1.0]];
        for (lines, expected) in [
            (vec![(good, 1.0), (short, 1.0)], "line 1: 1 point(s)"),
            (vec![(nan, 1.0)], "line 0: point 1 has a non-finite"),
            (vec![(good, f64::INFINITY)], "non-finite elevation"),
        ] {
            let error = write_lines(&path, LineFormat::GeoJson, &lines, CrsRef::default())
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(error.contains(expected), "{error}");
        }
        assert!(std::fs::read_dir(dir.path()).expect("dir").next().is_none());
    }
}
