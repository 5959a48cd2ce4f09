//! Isocontours of a triangulated irregular network (TIN), the application of Schikore &
//! Bajaj, "Decimation of 2D Scalar Data with Error Control" (1995), §5: contouring the
//! decimated mesh instead of the dense grid gives nearly the same lines with far fewer
//! segments.
//!
//! A [`ContourMesh`] is a checked triangle mesh with heights (from any vertex list and
//! triangle list, or [`ContourMesh::from_grid`] for the full-resolution grid); [`contour`]
//! cuts it at each level by marching triangles and joins the segments into [`Polyline`]s.
//! No I/O, no GDAL: coordinates are whatever the caller gives (the `tinsmith` pipeline uses grid
//! positions and maps the result to world coordinates). [`ContourStitcher`] gives the same
//! lines for a mesh that arrives in pieces (tiles), holding only the lines.
//! [`simplify_indices`] is an opt-in Douglas–Peucker step for callers that trade exactness
//! on the TIN for fewer points.
//!
//! # Guarantees
//! - **On the TIN.** Every output point lies on a mesh edge where the edge's linear
//!   interpolation equals the level (see [`Polyline`]). So when the mesh is within `ε` of
//!   the grid's samples (as `tinsmith_core::decimate` guarantees), the lines are the exact
//!   contours of a surface within `ε` of every sample.
//! - **Joined.** Closed rings are closed (first point == last point); open lines end only
//!   on boundary edges (the domain's outline or a nodata hole), never in the interior.
//! - **Degenerate cases** are settled by one rule, a symbolic perturbation: a height equal
//!   to the level counts as above it. Contours then separate the vertices below the level
//!   from those at or above it; a line touching a vertex at the level passes through that
//!   vertex exactly; a triangle flat at the level is uncut (the line runs along the edge of
//!   a flat area at the level); a vertex or a ridge of edges only touching the level makes
//!   no line, and a line does not run out along such a ridge and back; saddles
//!   need nothing more, as every crossed edge has exactly one crossing.
//! - **Deterministic.** The output depends only on the mesh and the levels (see
//!   [`contour`] for the order); nothing is hashed or threaded.
//!
//! # Example
//! ```
//! use tinsmith_contour::{contour, ContourMesh};
//! # fn main() -> Result<(), tinsmith_contour::Error> {
//! // A cone: height = distance from the centre of a 9 x 9 grid.
//! let values: Vec<f64> = (0..81)
//!     .map(|i| (((i % 9) as f64 - 4.0).powi(2) + ((i / 9) as f64 - 4.0).powi(2)).sqrt())
//!     .collect();
//! let mesh = ContourMesh::from_grid(9, 9, &values)?;
//! let lines = contour(&mesh, &[2.5])?;
//! assert_eq!(lines.len(), 1);
//! assert!(lines[0].is_closed());
//! assert_eq!(lines[0].points().first(), lines[0].points().last());
//! # Ok(())
//! # }
//! ```

mod crossing;
mod error;
mod join;
mod levels;
mod mesh;
mod polyline;
mod regularize;
mod simplify;
mod stitch;

pub use error::{Error, Result};
pub use join::contour;
pub use levels::{interval_levels, sorted_levels, MAX_LEVELS};
pub use mesh::ContourMesh;
pub use polyline::Polyline;
pub use simplify::simplify_indices;
pub use stitch::ContourStitcher;
