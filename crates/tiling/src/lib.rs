//! Tiled decimation: rasters of any size meshed in bounded memory, in parallel, into one
//! crack-free TIN within the error bound, deterministically.
//!
//! The raster is cut into tiles that share their edge rows and columns ([`TilePlan`]).
//! Each shared edge is simplified once as a 1-D polyline ([`EdgeProfile`]) from data both
//! of its tiles read identically, so both keep the same edge vertices; each tile is then
//! decimated with those vertices locked (`tinsmith_core::decimate_with_border`), checked by
//! the independent verifier, and streamed, in tile order, into a [`TileSink`]:
//! [`WeldedWriter`] writes one welded mesh (each shared vertex once, global indices),
//! [`PerTileWriter`] one file per tile, [`MeshCollector`] keeps the welded mesh in memory.
//! [`mesh_tiles`] documents the guarantees.
//!
//! Samples come from a [`TileSource`]: [`RasterSource`] reads a GDAL raster a window at a
//! time (one dataset per worker thread), [`GridSource`] cuts a grid in memory.
//!
//! # Example
//! ```
//! use tinsmith_core::{DecimationOptions, Grid};
//! use tinsmith_formats::{read_mesh, MeshFormat};
//! use tinsmith_georef::Placement;
//! use tinsmith_tiling::{mesh_tiles, GridSource, TileOptions, WeldedWriter};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // A 9 x 7 grid: a gentle bowl.
//! let values = (0..63).map(|i| ((i % 9 - 4) * (i % 9 - 4) + (i / 9 - 3) * (i / 9 - 3)) as f64);
//! let grid = Grid::new(9, 7, values.collect())?;
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("bowl.ply");
//! let mut writer = WeldedWriter::create(&path, MeshFormat::Ply, None, Placement::Pixel)?;
//! let options = TileOptions::new(DecimationOptions::new(0.5)).with_tile_size(4).with_threads(2);
//! let report = mesh_tiles(&GridSource::new(&grid), &options, &mut writer, &mut |_| {})?;
//! writer.finish()?;
//!
//! assert_eq!(report.plan.len(), 6); // 3 x 2 tiles of at most 4 x 4 samples
//! assert!(report.measured_max_error <= 0.5);
//! assert_eq!(read_mesh(&path)?.triangles.len() as u64, report.final_triangles);
//! # Ok(())
//! # }
//! ```

mod collector;
mod edge;
mod engine;
mod error;
mod halo;
mod memory;
mod ordered_pool;
mod per_tile_writer;
mod plan;
#[cfg(feature = "raster")]
mod raster_source;
mod sink;
mod source;
mod tin_check;
mod vertex_ids;
mod welded_writer;

pub use collector::MeshCollector;
pub use edge::{edge_limit, edge_span, EdgeProfile, EdgeRule};
pub use engine::{
    mesh_tiles, worker_count, TileOptions, TileProgress, TilesReport, DEFAULT_TILE_SIZE,
};
pub use error::{Error, Result};
pub use memory::{
    available_bytes, BYTES_PER_START_TRIANGLE, COUNT_TARGET_BYTES_PER_SAMPLE,
    WHOLE_GRID_BYTES_PER_SAMPLE,
};
pub use per_tile_writer::PerTileWriter;
pub use plan::{TileIndex, TilePlan, TileWindow};
#[cfg(feature = "raster")]
pub use raster_source::{RasterReader, RasterSource};
pub use sink::{FinishedTile, SinkError, TileSink};
pub use source::{GridSource, ReadError, TileSource, WindowRead};
pub use tin_check::{check_tin, check_variable};
pub use welded_writer::WeldedWriter;
