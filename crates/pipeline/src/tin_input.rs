//! Existing TINs as input of `tinsmith mesh` and `tinsmith verify`: a mesh file (PLY,
//! OBJ, LandXML, FlatGeobuf) read by `tinsmith_formats`, its vertices put on a lattice
//! and its own triangles checked ([`tinsmith_points::tin_points`]).

use std::path::Path;

use tinsmith_formats::MeshFormat;
use tinsmith_points::TinPoints;

use crate::error::bail;
use crate::Feedback;
use crate::Result;

/// The mesh formats read as TIN input, by extension.
const TIN_FORMATS: [MeshFormat; 4] = [
    MeshFormat::Ply,
    MeshFormat::Obj,
    MeshFormat::LandXml,
    MeshFormat::FlatGeobuf,
];

/// Whether `path` is read as an existing TIN (by its extension: `.ply`, `.obj`, `.xml`,
/// `.fgb`).
pub fn is_tin_input(path: &Path) -> bool {
    MeshFormat::from_path(path).is_ok_and(|f| TIN_FORMATS.contains(&f))
}

/// The TIN of `path` on its lattice, and the CRS it records as WKT: the file's (a WKT, or
/// an EPSG code), else a `.prj` sidecar beside it. Notes dropped and merged vertices on
/// `feedback`.
pub(crate) fn read_tin(
    path: &Path,
    feedback: &dyn Feedback,
) -> Result<(TinPoints, Option<String>)> {
    let mesh = tinsmith_formats::read_mesh(path)?;
    let tin = tinsmith_points::tin_points(path, &mesh.vertices, &mesh.triangles)?;
    if tin.unused > 0 {
        feedback.note(&format!(
            "{}: {} vertices in no triangle are not part of the surface: dropped",
            path.display(),
            tin.unused
        ));
    }
    if tin.merged > 0 {
        feedback.note(&format!(
            "{}: {} copies of vertices (same x, y, z) merged",
            path.display(),
            tin.merged
        ));
    }
    let crs = match (mesh.crs_wkt, mesh.epsg) {
        (Some(wkt), _) if !wkt.trim().is_empty() => Some(wkt),
        (_, Some(code)) => Some(tinsmith_raster::crs_wkt(&format!("EPSG:{code}"))?),
        _ => {
            let prj = path.with_extension("prj");
            match std::fs::read_to_string(&prj) {
                Ok(text) if !text.trim().is_empty() => Some(text.trim().to_owned()),
                Ok(_) => None,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
                Err(e) => bail!("{}: cannot read: {e}", prj.display()),
            }
        }
    };
    Ok((tin, crs))
}
