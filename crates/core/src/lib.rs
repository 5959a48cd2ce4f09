//! Error-bounded decimation of 2D scalar grids into triangulated irregular networks.
//!
//! This crate implements the vertex-removal decimation of Schikore & Bajaj,
//! "Decimation of 2D Scalar Data with Error Control" (Purdue CSD-TR-95-004, 1995).
//! It knows only the grid of samples, the mesh topology and heights: no files, no GDAL.
//!
//! # Guarantee
//! For every valid sample of the input [`Grid`] that lies in the domain (a corner of a cell
//! whose four corners are valid), the linear interpolation of the output [`Tin`] at the
//! sample's position differs from the sample value by at most
//! [`DecimationOptions::max_error`]. The domain (the union of valid cells) is never changed.
//!
//! [`decimate_scatter`] decimates a triangulation of scattered points (a [`Scatter`] on an
//! integer lattice, the paper's general case) with the same stars, classes and hole
//! retriangulation: every point is within the bound of the output's interpolation at its
//! position, and the triangulation's outline is never changed.
//!
//! # Example
//! ```
//! use tinsmith_core::{decimate, DecimationOptions, Grid};
//! # fn main() -> Result<(), tinsmith_core::Error> {
//! // A tilted plane: every vertex but the domain's corners can go.
//! let values: Vec<f64> = (0..25).map(|i| (i % 5) as f64 + 2.0 * (i / 5) as f64).collect();
//! let grid = Grid::new(5, 5, values)?;
//! let result = decimate(&grid, &DecimationOptions::new(0.5))?;
//! assert_eq!(result.tin.triangles().len(), 2);
//! # Ok(())
//! # }
//! ```

mod coverage;
mod decimate;
mod edge_limit;
mod error;
mod error_bound;
mod exact;
mod extend;
mod flips;
mod grid;
mod hole;
mod insert;
mod levels;
mod mesh;
mod options;
mod predicates;
mod rtin;
mod scatter;
mod strips;
mod tin;
mod variables;

pub use decimate::{
    decimate, decimate_with_border, decimate_with_progress, effective_limit, vertex_raise,
    Decimation, DecimationReport, Progress, MAX_ABS_HEIGHT, RAISED_HEIGHT_SHARE,
};
pub use edge_limit::{EdgeLimit, EdgeMetric};
pub use error::{Error, Result};
pub use error_bound::ErrorBound;
pub use grid::Grid;
pub use mesh::VertexClass;
pub use options::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};
pub use scatter::{
    decimate_scatter, decimate_scatter_constrained, Scatter, ScatterReport, ScatterTin,
    MAX_SCATTER_COORDINATE,
};
pub use tin::{Tin, TinVertex};
pub use variables::Variable;
