//! Point layers read as `[x, y, z]` in the layer's own CRS: survey points as a TIN's input.

use std::path::Path;

use gdal::vector::{Geometry, LayerAccess};

use crate::error::{Error, Result};
use crate::polygons::{open_vector, open_vector_file, same_layer_crs};

/// The points of a vector file, in its own CRS.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct PointLayer {
    /// Each point's x, y and height, in layer and feature order (multipoints flattened).
    pub points: Vec<[f64; 3]>,
    /// The CRS of the layers as WKT, if they declare one.
    pub crs_wkt: Option<String>,
}

/// Whether GDAL opens `path` as a vector file whose first layer declares point (or
/// multipoint) geometries, or declares no one type and its first feature is a point.
pub fn is_point_layer(path: &Path) -> bool {
    use gdal_sys::OGRwkbGeometryType as T;
    let Ok(dataset) = open_vector(path) else {
        return false;
    };
    let Ok(mut layer) = dataset.layer(0) else {
        return false;
    };
    let declared = layer
        .defn()
        .geom_fields()
        .next()
        .map(|f| gdal::vector::geometry_type_flatten(f.field_type()));
    let kind = match declared {
        Some(T::wkbUnknown) => layer
            .features()
            .find_map(|f| f.geometry().map(|g| g.geometry_type()))
            .map(gdal::vector::geometry_type_flatten),
        other => other,
    };
    matches!(kind, Some(T::wkbPoint | T::wkbMultiPoint))
}

/// Reads every point of every layer of the vector file at `path` (GeoPackage, Shapefile,
/// FlatGeobuf... as GDAL reads them). The height is the attribute `z_field` when given,
/// else the geometry's Z. Features without a geometry are skipped.
///
/// # Errors
/// [`Error::NotFound`] when nothing is at `path`; [`Error::Lines`] naming `path` when GDAL
/// cannot open it as a vector file, a geometry is not a point, the points have no Z and
/// no `z_field` is given, the field does not exist or is empty on a feature, layers
/// declare different CRSs, or a value is not finite.
pub fn read_point_layer(path: &Path, z_field: Option<&str>) -> Result<PointLayer> {
    let bad = |reason: String| Error::Lines {
        path: path.to_path_buf(),
        reason,
    };
    let dataset = open_vector_file(path)?;
    let mut out = PointLayer::default();
    let mut crs: Option<Option<String>> = None;
    for mut layer in dataset.layers() {
        same_layer_crs(&mut crs, &layer, path)?;
        let field = match z_field {
            Some(name) => Some(layer.defn().field_index(name).map_err(|_| {
                bad(format!(
                    "layer {} has no field {name} (--z-field)",
                    layer.name()
                ))
            })?),
            None => None,
        };
        for (k, feature) in layer.features().enumerate() {
            let Some(geometry) = feature.geometry() else {
                continue;
            };
            let z = match field {
                Some(i) => Some(
                    feature
                        .field_as_double(i)
                        .ok()
                        .flatten()
                        .ok_or_else(|| bad(format!("feature {k} has no value in --z-field")))?,
                ),
                None => None,
            };
            collect(geometry, z, &mut out.points, &bad)?;
        }
    }
    if let Some(p) = out.points.iter().find(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(bad(format!("point {p:?} is not finite")));
    }
    out.crs_wkt = crs.flatten().filter(|w| !w.trim().is_empty());
    Ok(out)
}

/// Appends the points of `geometry` (a point or a multipoint), with height `z` or their
/// own Z.
fn collect(
    geometry: &Geometry,
    z: Option<f64>,
    out: &mut Vec<[f64; 3]>,
    bad: &dyn Fn(String) -> Error,
) -> Result<()> {
    use gdal_sys::OGRwkbGeometryType as T;
    let kind = gdal::vector::geometry_type_flatten(geometry.geometry_type());
    match kind {
        T::wkbPoint => {
            let has_z = gdal::vector::geometry_type_has_z(geometry.geometry_type());
            let (x, y, own) = geometry.get_point(0);
            let Some(h) = z.or(has_z.then_some(own)) else {
                return Err(bad(
                    "the points have no Z: give the height attribute with --z-field NAME"
                        .to_owned(),
                ));
            };
            out.push([x, y, h]);
            Ok(())
        }
        T::wkbMultiPoint => {
            for i in 0..geometry.geometry_count() {
                collect(&geometry.get_geometry(i), z, out, bad)?;
            }
            Ok(())
        }
        other => Err(bad(format!(
            "holds a {} geometry, not points",
            gdal::vector::geometry_type_to_name(other)
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_from_the_geometry_or_a_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.geojson");
        std::fs::write(
            &path,
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{"h":5.5},"geometry":{"type":"Point","coordinates":[1,2,3]}},
            {"type":"Feature","properties":{"h":6.5},"geometry":{"type":"MultiPoint","coordinates":[[4,5,6],[7,8,9]]}}]}"#,
        )
        .unwrap();
        assert!(is_point_layer(&path));
        let own = read_point_layer(&path, None).unwrap();
        assert_eq!(
            own.points,
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]
        );
        let field = read_point_layer(&path, Some("h")).unwrap();
        assert_eq!(field.points[2], [7.0, 8.0, 6.5]);
        let e = read_point_layer(&path, Some("nope"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("p.geojson") && e.contains("no field nope"),
            "{e}"
        );
    }

    #[test]
    fn flat_points_without_a_field_and_lines_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let flat = dir.path().join("flat.geojson");
        std::fs::write(
            &flat,
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[1,2]}}]}"#,
        )
        .unwrap();
        let e = read_point_layer(&flat, None).unwrap_err().to_string();
        assert!(e.contains("flat.geojson") && e.contains("--z-field"), "{e}");
        let line = dir.path().join("line.geojson");
        std::fs::write(
            &line,
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[1,2],[3,4]]}}]}"#,
        )
        .unwrap();
        assert!(!is_point_layer(&line));
        let e = read_point_layer(&line, None).unwrap_err().to_string();
        assert!(e.contains("not points"), "{e}");
    }
}
