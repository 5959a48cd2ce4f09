//! Writes and reads triangulated irregular networks as mesh files (PLY, OBJ, STL, glTF,
//! GeoJSON, FlatGeobuf, LandXML; see [`MeshFormat`]), and contour lines as line features
//! ([`write_lines`]).
//!
//! A mesh is given as plain slices ([`MeshRef`]): world `[x, y, z]` vertices, `[u32; 3]`
//! triangles in the orientation to be written, and an optional CRS as WKT. This crate knows
//! nothing about how the mesh was made; of the other tinsmith crates it depends only on
//! `tinsmith-output`, which puts the bytes on disk.
//!
//! # Guarantees
//! - **Atomic output.** [`write_mesh`] (and [`MeshStreamWriter`], which takes the mesh in
//!   pieces) writes through `tinsmith_output`: a temporary file next to the target renamed
//!   into place; a file it replaces keeps its permissions. After an error there is no
//!   partial file and no temporary file; an existing file at the target keeps its content.
//! - **Exact round trip in the double-precision formats.** [`read_mesh`] of a PLY, OBJ,
//!   FlatGeobuf or LandXML file written by [`write_mesh`] (and a GeoJSON one, which prints
//!   the shortest decimals) returns the same coordinates bit for bit (PLY stores `double`s,
//!   the text formats the shortest decimal that parses back to the same `f64`), the same
//!   triangles in the same order and orientation, and the CRS on one line. STL and glTF
//!   store float32 offsets from a [`LocalOrigin`]: they read back as the origin plus those
//!   offsets.
//! - **Validated input.** [`write_mesh`] refuses meshes with out-of-range indices or
//!   non-finite coordinates before creating any file; [`read_mesh`] returns only meshes
//!   with finite coordinates and in-range indices, and reports every malformed file as an
//!   [`Error`] naming the file, never by panicking.
//!
//! # Formats
//! See [`MeshFormat`] for each: for example [`MeshFormat::Ply`] is written as
//! `binary_little_endian 1.0` (`double` x, y, z; `list uchar int vertex_indices`; `comment
//! crs <wkt>`) and read as ASCII or binary; [`MeshFormat::Obj`] as `v`/`f` lines with a
//! `# crs: <wkt>` comment.
//!
//! # Example
//! ```
//! use tinsmith_formats::{read_mesh, write_mesh, MeshFormat, MeshRef};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("tile.ply");
//!
//! let vertices = [
//!     [500_000.0, 4_649_776.0, 312.5],
//!     [500_030.0, 4_649_776.0, 313.25],
//!     [500_000.0, 4_649_806.0, 311.0],
//! ];
//! let triangles = [[0, 1, 2]];
//! let mesh = MeshRef::new(&vertices, &triangles).with_crs_wkt("EPSG:32633");
//! write_mesh(&path, MeshFormat::from_path(&path)?, mesh)?;
//!
//! let back = read_mesh(&path)?;
//! assert_eq!(back.vertices, vertices);
//! assert_eq!(back.triangles, triangles);
//! assert_eq!(back.crs_wkt.as_deref(), Some("EPSG:32633"));
//! # Ok(())
//! # }
//! ```

mod antimeridian;
mod error;
mod fgb;
mod file;
mod format;
mod geojson;
mod glb;
mod landxml;
mod lines;
mod mesh;
mod obj;
mod options;
mod origin;
mod ply;
mod stl;
mod stream;
mod weld;

pub use antimeridian::cut_at_antimeridian;
pub use error::{Error, Result};
pub use file::{prj_path, read_mesh, read_mesh_as, read_mesh_bytes, write_mesh, write_mesh_with};
pub use format::MeshFormat;
pub use glb::write_glb_start;
pub use lines::{write_lines, write_multilines, CrsRef, LineFormat, LinePoint};
pub use mesh::{Mesh, MeshRef, VertexAttribute};
pub use options::WriteOptions;
pub use origin::LocalOrigin;
pub use stream::MeshStreamWriter;

/// EPSG 4326 for EPSG 4979 (WGS84 with ellipsoidal heights, as ogr2ogr labels WGS84 files
/// whose positions have a z): in GeoJSON and FlatGeobuf both are longitude, latitude in
/// degrees, and a mesh's heights are its raster's values either way. Other codes as given.
pub(crate) fn wgs84_code(code: u32) -> u32 {
    if code == 4979 {
        4326
    } else {
        code
    }
}
