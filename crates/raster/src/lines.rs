//! Line and polygon layers read as lines in the layer's own coordinates: breaklines and
//! outlines that a TIN keeps as edges.

use std::path::Path;

use gdal::vector::{Geometry, LayerAccess};

use crate::error::{Error, Result};
use crate::polygons::{open_vector_file, same_layer_crs};

/// The lines of a vector file, in its own CRS.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct LineLayer {
    /// Each line string or polygon ring as `[x, y, z]` vertices in file order (a ring
    /// closed: its last vertex repeats its first); `z` is 0 when the layer has no heights.
    pub lines: Vec<Vec<[f64; 3]>>,
    /// Whether the geometries carry heights (a Z or 2.5D geometry type).
    pub has_z: bool,
    /// Whether every geometry is a polygon (or multipolygon): an outline with holes.
    pub polygons: bool,
    /// The CRS of the layers as WKT, if they declare one.
    pub crs_wkt: Option<String>,
}

/// Reads every line string and polygon ring of every layer of the vector file at `path`
/// (GeoPackage, Shapefile, GeoJSON, FlatGeobuf... as GDAL reads them), in layer and
/// feature order; multi-geometries and collections are flattened. Features without a
/// geometry are skipped.
///
/// # Errors
/// [`Error::NotFound`] when nothing is at `path`; [`Error::Lines`] naming `path` when GDAL
/// cannot open it as a vector file, a geometry is a point (or anything but lines and
/// polygons), layers declare different CRSs, a coordinate is not finite, some geometries
/// have heights and others not, or there is no line at all.
pub fn read_lines(path: &Path) -> Result<LineLayer> {
    let bad = |reason: String| Error::Lines {
        path: path.to_path_buf(),
        reason,
    };
    let dataset = open_vector_file(path)?;
    let mut out = LineLayer {
        polygons: true,
        ..LineLayer::default()
    };
    let mut crs: Option<Option<String>> = None;
    let mut heights: Option<bool> = None;
    for mut layer in dataset.layers() {
        same_layer_crs(&mut crs, &layer, path)?;
        for feature in layer.features() {
            let Some(geometry) = feature.geometry() else {
                continue;
            };
            let has_z = gdal::vector::geometry_type_has_z(geometry.geometry_type());
            if *heights.get_or_insert(has_z) != has_z {
                return Err(bad(
                    "some geometries have heights (Z) and others not".to_owned()
                ));
            }
            collect(geometry, &mut out, &bad)?;
        }
    }
    if out.lines.is_empty() {
        return Err(bad("holds no line or polygon".to_owned()));
    }
    out.has_z = heights.unwrap_or(false);
    out.crs_wkt = crs.flatten().filter(|w| !w.trim().is_empty());
    Ok(out)
}

/// Appends the lines of `geometry` (a line string, a polygon's rings, or the parts of a
/// multi-geometry or collection).
fn collect(geometry: &Geometry, out: &mut LineLayer, bad: &dyn Fn(String) -> Error) -> Result<()> {
    use gdal_sys::OGRwkbGeometryType as T;
    let kind = gdal::vector::geometry_type_flatten(geometry.geometry_type());
    match kind {
        T::wkbLineString | T::wkbLinearRing => {
            out.polygons = false;
            push_line(geometry, out, bad)
        }
        T::wkbPolygon => {
            for i in 0..geometry.geometry_count() {
                push_line(&geometry.get_geometry(i), out, bad)?;
            }
            Ok(())
        }
        T::wkbMultiLineString | T::wkbMultiPolygon | T::wkbGeometryCollection => {
            for i in 0..geometry.geometry_count() {
                collect(&geometry.get_geometry(i), out, bad)?;
            }
            Ok(())
        }
        other => Err(bad(format!(
            "holds a {} geometry, not lines or polygons",
            gdal::vector::geometry_type_to_name(other)
        ))),
    }
}

fn push_line(line: &Geometry, out: &mut LineLayer, bad: &dyn Fn(String) -> Error) -> Result<()> {
    let n = line.point_count();
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        let (x, y, z) = line.get_point(i as i32);
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(bad(format!("coordinate ({x}, {y}, {z}) is not finite")));
        }
        points.push([x, y, z]);
    }
    if !points.is_empty() {
        out.lines.push(points);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geojson(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn lines_polygons_and_heights_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let lines = geojson(
            &dir,
            "l.geojson",
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0,1],[2,0,3]]}},
            {"type":"Feature","properties":{},"geometry":{"type":"MultiLineString","coordinates":[[[5,5,0],[6,6,1]],[[7,7,2],[8,8,2]]]}}]}"#,
        );
        let read = read_lines(&lines).unwrap();
        assert!(read.has_z && !read.polygons);
        assert_eq!(read.lines.len(), 3);
        assert_eq!(read.lines[0], vec![[0.0, 0.0, 1.0], [2.0, 0.0, 3.0]]);
        let polygon = geojson(
            &dir,
            "p.geojson",
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4],[0,0]],[[1,1],[2,1],[2,2],[1,1]]]}}]}"#,
        );
        let read = read_lines(&polygon).unwrap();
        assert!(!read.has_z && read.polygons);
        assert_eq!(read.lines.len(), 2);
        assert_eq!(read.lines[1].len(), 4);
    }

    #[test]
    fn points_and_missing_files_are_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let points = geojson(
            &dir,
            "pts.geojson",
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[0,0]}}]}"#,
        );
        let e = read_lines(&points).unwrap_err().to_string();
        assert!(e.contains("pts.geojson") && e.contains("Point"), "{e}");
        let e = read_lines(&dir.path().join("none.gpkg"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("none.gpkg") && e.contains("no such file"), "{e}");
        let text = geojson(&dir, "t.geojson", "not json");
        let e = read_lines(&text).unwrap_err().to_string();
        assert!(e.contains("t.geojson") && e.contains("vector"), "{e}");
    }
}
