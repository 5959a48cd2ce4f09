//! A brute-force, independent check of a TIN against the grid it approximates.
//!
//! [`verify`] rasterizes every triangle over the grid's integer samples, measures the true
//! vertical error `|sample - interpolation|` at each one, and checks that the triangles
//! tile the grid's domain (the union of cells whose four corners are valid) with the
//! expected orientation. It takes plain slices and shares no code with the decimator, so
//! it can judge the decimator's guarantee: "every domain sample is within `max_error` of the
//! TIN's linear interpolation".
//!
//! # Guarantees
//! - All geometry is exact: orientation, inside tests and barycentric weights use integer
//!   arithmetic (`i128`) on the grid positions, never floating point. A sample on an edge
//!   or vertex is inside (closed triangles).
//! - The interpolation uses the mesh's own heights, so a vertex whose height differs from
//!   its sample shows up as error. At a vertex the height is used exactly; elsewhere the
//!   weighted mean is evaluated in `f64` (exact weights below 2^53).
//! - Every finding is counted and located in the [`Report`]; only inconsistent input
//!   lengths are errors ([`VerifyError`]). The result is deterministic.
//!
//! # Example
//! ```
//! use tinsmith_verify::{verify, GridRef, MeshRef, VerifyOptions};
//! # fn main() -> Result<(), tinsmith_verify::VerifyError> {
//! // A 3x3 grid, flat except a bump of 1.0 at the centre.
//! let values = [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
//! // Two triangles over the four corners, counter-clockwise in grid coordinates.
//! let positions = [[0, 0], [2, 0], [2, 2], [0, 2]];
//! let heights = [0.0; 4];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//!
//! let report = verify(
//!     GridRef::new(3, 3, &values),
//!     MeshRef::new(&positions, &heights, &triangles),
//!     &VerifyOptions::new().with_max_error(0.5),
//! )?;
//! assert!(report.mesh_is_valid());
//! assert_eq!(report.max_error, 1.0);
//! let at = report.max_error_at.expect("samples were measured");
//! assert_eq!((at.x, at.y), (1, 1));
//! assert!(!report.passed(), "{:?}", report.problems);
//! # Ok(())
//! # }
//! ```

mod breaklines;
mod coverage;
mod edges;
mod error;
mod grid;
mod mesh;
mod options;
mod outline;
mod points;
mod predicates;
mod problems;
mod report;
mod scan_convert;
mod surface;
mod variables;
mod verify;

pub use breaklines::{verify_breaklines, BreaklinesReport};
pub use error::{Result, VerifyError};
pub use grid::GridRef;
pub use mesh::MeshRef;
pub use options::{Orientation, VerifyOptions};
pub use outline::inside_outline;
pub use points::{verify_points, PointsReport};
pub use report::{ErrorLocation, Report};
pub use surface::{surface, surface_at};
pub use variables::verify_variable;
pub use verify::verify;
