//! Point clouds in: LAS/LAZ (the `las` crate, LAZ through its `laz` feature) and XYZ/CSV
//! text, streamed into compact lattice arrays (16 bytes of position and 8 of height per
//! point), deduplicated by a rule, and Delaunay-triangulated with spade (constrained by
//! breaklines with [`constrained_delaunay`]); or an existing
//! TIN's vertices put on a lattice with its own triangles checked ([`tin_points`]).
//!
//! Positions are kept as integers on a lattice: a LAS file's own integers (`X`, `Y`,
//! shifted to start at 0), or for text the lattice of spacing `10^-d`, `d` the most
//! decimals written. Every lattice coordinate is below 2^31, so the decimator's exact
//! `i64` predicates apply to them unchanged.
//!
//! # Example
//! ```no_run
//! use tinsmith_points::{dedupe, delaunay, read_points, Duplicates, ReadOptions};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mut cloud = read_points("survey.laz".as_ref(), &ReadOptions::default())?;
//! let merged = dedupe(&mut cloud, Duplicates::Mean);
//! let triangles = delaunay(&cloud)?;
//! println!("{} points ({merged} merged), {} triangles", cloud.xy.len(), triangles.len());
//! # Ok(())
//! # }
//! ```

mod breaklines;
mod cloud;
mod dedupe;
mod delaunay;
mod error;
mod las_file;
mod text;
mod tin;
mod world;

use std::path::Path;

pub use breaklines::{constrained_delaunay, BreaklineError, ConstrainedTriangulation, Constraints};
pub use cloud::{ClassChoice, FileCrs, PointCloud, MAX_LATTICE};
pub use dedupe::{dedupe, Duplicates};
pub use delaunay::{delaunay, TriangulationError};
pub use error::{Error, Result};
pub use tin::{tin_points, TinPoints};
pub use world::world_cloud;

/// Which points of a LAS file to read (text files have no classes).
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct ReadOptions {
    /// Keep only these ASPRS classes; `None`: ground (class 2) when the file has any
    /// ground point, else every class.
    pub classes: Option<Vec<u8>>,
    /// Drop points flagged withheld.
    pub no_withheld: bool,
}

/// Whether `path`'s extension names a point file this crate reads.
pub fn is_point_file(path: &Path) -> bool {
    kind(path).is_some()
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Las,
    Text,
}

fn kind(path: &Path) -> Option<Kind> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "las" | "laz" => Some(Kind::Las),
        "xyz" | "csv" | "txt" => Some(Kind::Text),
        _ => None,
    }
}

/// Reads the points of a LAS/LAZ or text file, streaming (the file is never held in
/// memory; the points go straight into the cloud's arrays).
///
/// # Errors
/// [`Error::NotPoints`] for another extension; [`Error::Io`], [`Error::Las`] when the file
/// cannot be read (a truncated LAZ among them); [`Error::Format`] for a LAS whose header
/// declares another number of points than it holds, a text line that is not `x y z`
/// numbers, a NaN or infinite value, or positions too far apart for 32-bit lattice
/// differences.
pub fn read_points(path: &Path, options: &ReadOptions) -> Result<PointCloud> {
    match kind(path) {
        Some(Kind::Las) => las_file::read_las(path, options),
        Some(Kind::Text) => text::read_text(path),
        None => Err(Error::NotPoints {
            path: path.to_path_buf(),
        }),
    }
}
