//! What can go wrong building a terrain pyramid.

use std::path::PathBuf;

/// What can go wrong while building a pyramid.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TerrainError {
    /// Reading or reprojecting the input failed.
    #[error(transparent)]
    Raster(#[from] tinsmith_raster::Error),
    /// The options make no sense (the message says which).
    #[error("{0}")]
    Options(String),
    /// Heights (largest magnitude, widest range of a tile) beyond what quantized-mesh
    /// tiles, whose height ranges are stored in `f32`, can hold.
    #[error(
        "heights up to {max_abs:e} in magnitude (tiles spanning up to {widest:e}) are beyond what \
         quantized-mesh tiles can hold (their height range is stored in f32)"
    )]
    HeightsBeyondF32 {
        /// The largest magnitude of a valid height.
        max_abs: f64,
        /// The widest range of valid heights of a tile.
        widest: f64,
    },
    /// The thread pool could not start.
    #[error("cannot start {threads} worker threads")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Rayon's reason.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
    /// The core refused a tile.
    #[error("tile {z}/{x}/{y}: decimation failed")]
    Decimate {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The core's reason.
        #[source]
        source: tinsmith_core::Error,
    },
    /// The verifier refused a tile, or found it outside the bound (an internal error).
    #[error("tile {z}/{x}/{y}: verification failed ({problems})")]
    Verify {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// What the verifier found.
        problems: String,
    },
    /// The encoder refused a tile (an internal error).
    #[error("tile {z}/{x}/{y}: encoding failed")]
    Encode {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The encoder's reason.
        #[source]
        source: crate::quantized_mesh::EncodeError,
    },
    /// Writing the output failed.
    #[error("{}: cannot write", path.display())]
    Output {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

/// Result of [`crate::build_terrain`].
pub type TerrainResult<T> = std::result::Result<T, TerrainError>;
