//! The error type of point reading.

use std::path::PathBuf;

/// What can go wrong reading points; every variant names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The LAS/LAZ reader refused the file (bad header, truncated or corrupt data).
    #[error("{}: not a readable LAS/LAZ file (truncated or corrupt?): {source}", path.display())]
    Las {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: las::Error,
    },
    /// The file's content is not usable points: the message says where and why.
    #[error("{}: {problem}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong (with a line number for text).
        problem: String,
    },
    /// The extension is none of `.las`, `.laz`, `.xyz`, `.csv`, `.txt`.
    #[error("{}: not a point file (expected .las, .laz, .xyz, .csv or .txt)", path.display())]
    NotPoints {
        /// The file.
        path: PathBuf,
    },
}

/// Result of the fallible functions of this crate.
pub type Result<T> = std::result::Result<T, Error>;

pub(crate) fn format_error(path: &std::path::Path, problem: impl Into<String>) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        problem: problem.into(),
    }
}
