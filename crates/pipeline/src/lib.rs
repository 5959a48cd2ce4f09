//! The tinsmith commands as library calls: a raster in, a verified TIN, contour lines or a
//! terrain pyramid out. Every run takes plain values ([`MeshJob`], [`ContourJob`],
//! [`VerifyJob`]; for [`tiles`], paths and `tinsmith_terrain::TerrainOptions`; for
//! [`serve`], [`ServeOptions`]) and a [`Feedback`] for its notes and progress; the
//! `tinsmith` binary parses flags into those values, draws the feedback, prints results
//! and maps errors to exit codes.
//!
//! What every run guarantees:
//! - a mesh is written only after the independent verifier (`tinsmith-verify`) has
//!   measured it within the bound at every valid sample, with its heights as the file
//!   will hold them: float32 formats (STL, glTF) get a tighter decimation bound
//!   ([`FormatPlan`]) so that the file, not only the mesh in memory, keeps the bound;
//! - bad input fails before long work where it can, with a message naming the file;
//! - outputs are written through temporary files renamed into place, so a failed run
//!   leaves the old outputs untouched;
//! - the same job gives byte-identical files.
//!
//! ```no_run
//! use tinsmith_pipeline::{mesh, MeshJob, Silent};
//!
//! let mut job = MeshJob::new("dem.tif");
//! job.output = Some("dem.ply".into());
//! job.decimation.max_error = Some(0.5);
//! mesh(&job, &Silent)?;
//! # Ok::<(), tinsmith_pipeline::Error>(())
//! ```

mod contour;
mod error;
mod feedback;
mod format_plan;
mod jobs;
mod memory;
mod mesh;
mod mesh_file;
mod output_paths;
mod points;
mod preview;
mod report;
mod scan;
mod serve;
mod tiled_mesh;
mod tiles;
mod tin_input;
mod transform_check;
mod variables;
mod verify;
mod wgs84;

pub use contour::contour;
pub use error::{Error, Result};
pub use feedback::{Feedback, Silent};
pub use format_plan::{parse_format, FormatPlan};
pub use jobs::{
    ContourJob, ExportChoices, MeshJob, PointChoices, PreviewJob, TileFormat, VerifyJob,
    DEFAULT_TILE_SIZE,
};
pub use mesh::mesh;
pub use points::{duplicates_name, is_point_input, points_summary, verify_points_file};
pub use preview::{preview, preview_decimated, Previewed, WHOLE_READ_SAMPLES};
pub use scan::scan_raster;
pub use serve::{serve, ServeOptions};
pub use tiles::{base_raster, merge_tiles, tiles, tiles_shard, vertical_datum, water_source};
pub use tin_input::is_tin_input;
pub use tinsmith_choices::DecimationChoices;
pub use tinsmith_georef::readable;
pub use tinsmith_points::Duplicates;
pub use tinsmith_tiling::available_bytes;
pub use tinsmith_verify::PointsReport;
pub use variables::{attribute_variables, resolve_bands, BandVariable, VariableReport};
pub use verify::{verify, Verified};
