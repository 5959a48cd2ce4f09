//! The error type of the tiled engine: each variant says which tile or file it is about.

use std::path::PathBuf;

use crate::plan::TileIndex;

/// What can go wrong while meshing a raster tile by tile.
///
/// Split by what the caller does next: fix the options ([`Error::TileSize`],
/// [`Error::Options`], [`Error::Threads`]), pick another input ([`Error::TooNarrow`],
/// [`Error::AllNodata`], [`Error::Raster`], [`Error::Read`]), look at the output location
/// ([`Error::Output`], [`Error::Write`], [`Error::Sink`]), or report a bug
/// ([`Error::Decimate`], [`Error::Verify`], [`Error::VerifyFailed`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Tiles must have at least 2 samples per side.
    #[error("tile size must be at least 2 samples, got {size}")]
    TileSize {
        /// The size asked for.
        size: u32,
    },
    /// The raster has fewer than 2 columns or rows: no cell, nothing to triangulate.
    #[error("a {width}x{height} raster has no 2x2 block of samples to triangulate")]
    TooNarrow {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
    },
    /// The decimation options cannot be used for tiles.
    #[error("{0}")]
    Options(&'static str),
    /// The thread pool could not be built.
    #[error("cannot start {threads} worker threads")]
    Threads {
        /// Threads asked for (0 = one per core).
        threads: usize,
        /// Rayon's reason.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
    /// The band has no valid sample.
    #[error("{}: band {band} has no valid sample (all nodata)", path.display())]
    AllNodata {
        /// The raster file.
        path: PathBuf,
        /// The 1-based band.
        band: usize,
    },
    /// Opening or scanning the raster failed (the message names the file).
    #[cfg(feature = "raster")]
    #[error(transparent)]
    Raster(#[from] tinsmith_raster::Error),
    /// Reading a tile's samples failed.
    #[error("{tile}: reading its samples failed")]
    Read {
        /// The tile.
        tile: TileIndex,
        /// The reader's error (for a raster file it names the file).
        #[source]
        source: crate::ReadError,
    },
    /// The raster's heights are beyond what decimation takes
    /// ([`tinsmith_core::MAX_ABS_HEIGHT`]): refused before any tile, as an untiled run is.
    #[error(transparent)]
    Heights(tinsmith_core::Error),
    /// The core refused to decimate a tile (a shared edge sample it could not remove).
    #[error("{tile}: decimation failed")]
    Decimate {
        /// The tile.
        tile: TileIndex,
        /// The core's error.
        #[source]
        source: tinsmith_core::Error,
    },
    /// The verifier could not check a tile's mesh.
    #[error("{tile}: the verifier could not run")]
    Verify {
        /// The tile.
        tile: TileIndex,
        /// The verifier's error.
        #[source]
        source: tinsmith_verify::VerifyError,
    },
    /// A tile's mesh failed the independent verifier: an internal error; nothing is
    /// written.
    #[error("{tile}: internal error, the decimated tile failed verification ({problems})")]
    VerifyFailed {
        /// The tile.
        tile: TileIndex,
        /// The verifier's problems, joined.
        problems: String,
    },
    /// The welded mesh would have 2^32 - 1 vertices or more.
    #[error("{tile}: the welded mesh has too many vertices for 32-bit indices")]
    TooManyVertices {
        /// The tile at which the count overflowed.
        tile: TileIndex,
    },
    /// The sink refused a tile.
    #[error("{tile}: writing it failed")]
    Sink {
        /// The tile.
        tile: TileIndex,
        /// The sink's error.
        #[source]
        source: crate::SinkError,
    },
    /// The per-tile output directory cannot be used.
    #[error("{}: {reason}", path.display())]
    Output {
        /// The directory.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
        /// The I/O error, if there was one.
        #[source]
        source: Option<std::io::Error>,
    },
    /// Writing a mesh file failed (the message names the file).
    #[error(transparent)]
    Write(#[from] tinsmith_formats::Error),
}

/// Result of this crate's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;
