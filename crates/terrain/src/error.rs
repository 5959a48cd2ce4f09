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
    /// A tile's heights reach beyond what quantized-mesh tiles, whose height ranges are
    /// stored in `f32`, can hold.
    #[error(
        "tile {z}/{x}/{y}: heights up to {max_abs:e} in magnitude are beyond what quantized-mesh \
         tiles can hold (their height range is stored in f32)"
    )]
    HeightsBeyondF32 {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The largest magnitude of a valid height of the tile.
        max_abs: f64,
    },
    /// A tile's heights span more than its level's 16-bit height quanta can hold, or lie
    /// too far from 0 for its float32 minimum to be exact.
    #[error(
        "tile {z}/{x}/{y}: heights from {low} to {high} m span more than the {capacity} m that \
         16-bit quantized-mesh heights hold at this level's height step (or lie too far from 0 for it); is a \
         nodata value missing from the input, or is --quality too small? (Beyond the raster the \
         globe is at 0 m, which counts too, unless --data-only.)"
    )]
    TileHeights {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The tile's lowest vertex height.
        low: f64,
        /// Its highest.
        high: f64,
        /// The span the level's height quantum allows.
        capacity: f64,
    },
    /// The finest level has no tile with a valid cell: no terrain to write.
    #[error("no tile with a 2x2 block of valid samples at level {level}, the finest")]
    NoTerrain {
        /// The finest level.
        level: u8,
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
    /// The pyramid's destination failed (a directory, a container, an object store).
    #[error(transparent)]
    Store(#[from] tinsmith_store::StoreError),
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
