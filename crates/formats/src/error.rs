//! The error type of the format readers and writers: one enum, every variant names the file it is about.

use std::fmt;
use std::io;
use std::path::PathBuf;

use crate::format::MeshFormat;
use crate::lines::LineFormat;

/// What can go wrong while writing or reading a mesh file.
///
/// Variants are split by what the caller does next: fix the arguments
/// ([`Error::UnknownExtension`], [`Error::UnknownLineExtension`],
/// [`Error::UnknownFormatName`], [`Error::MissingDirectory`], [`Error::BadOption`]), fix the mesh or pick another format ([`Error::IndexOutOfRange`],
/// [`Error::NonFiniteVertex`], [`Error::TooManyVertices`], [`Error::TooManyTriangles`],
/// [`Error::InvalidLine`]), look at the environment ([`Error::Io`]) or at the input file
/// ([`Error::Malformed`], [`Error::Unsupported`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh format cannot be told from the path's extension.
    #[error(
        "{}: cannot tell the mesh format from the file extension (supported: {})",
        .path.display(),
        MeshFormat::supported_extensions()
    )]
    UnknownExtension {
        /// The path whose extension is missing or unknown.
        path: PathBuf,
    },
    /// The line format cannot be told from the path's extension.
    #[error(
        "{}: cannot tell the line format from the file extension (supported: {})",
        .path.display(),
        LineFormat::supported_extensions()
    )]
    UnknownLineExtension {
        /// The path whose extension is missing or unknown.
        path: PathBuf,
    },
    /// A format name (for example from a command-line flag) is not known.
    #[error(
        "unknown mesh format `{name}` (supported: {})",
        MeshFormat::supported_names()
    )]
    UnknownFormatName {
        /// The name as given.
        name: String,
    },
    /// The directory the output file should be created in does not exist.
    #[error("{}: output directory {} does not exist", .path.display(), .dir.display())]
    MissingDirectory {
        /// The output file.
        path: PathBuf,
        /// Its parent directory, which is missing.
        dir: PathBuf,
    },
    /// A triangle of the mesh to write refers to a vertex that does not exist.
    #[error(
        "{}: triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices",
        .path.display()
    )]
    IndexOutOfRange {
        /// The output file.
        path: PathBuf,
        /// Position of the triangle in the triangle slice.
        triangle: usize,
        /// The offending (0-based) vertex index.
        index: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// A vertex of the mesh to write has a NaN or infinite coordinate.
    #[error(
        "{}: vertex {vertex} has a non-finite coordinate {position:?}",
        .path.display()
    )]
    NonFiniteVertex {
        /// The output file.
        path: PathBuf,
        /// Position of the vertex in the vertex slice.
        vertex: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// The mesh has more vertices than the format can index.
    #[error(
        "{}: {count} vertices cannot be indexed in a {format} file (at most {max})",
        .path.display()
    )]
    TooManyVertices {
        /// The output file.
        path: PathBuf,
        /// The format being written.
        format: MeshFormat,
        /// Number of vertices in the mesh.
        count: usize,
        /// The most the format can index.
        max: usize,
    },
    /// The mesh has more triangles than the format can count.
    #[error(
        "{}: {count} triangles cannot be written to a {format} file (at most {max})",
        .path.display()
    )]
    TooManyTriangles {
        /// The output file.
        path: PathBuf,
        /// The format being written.
        format: MeshFormat,
        /// Number of triangles the file would hold.
        count: u64,
        /// The most the format can hold.
        max: u64,
    },
    /// A [`crate::WriteOptions`] value cannot be used with this mesh, such as an STL base
    /// that is not below every vertex, or an origin too long for the STL header.
    #[error("{}: {reason}", .path.display())]
    BadOption {
        /// The output file.
        path: PathBuf,
        /// What is wrong, naming the option.
        reason: String,
    },
    /// A line given to [`crate::write_lines`] cannot be written: fewer than two points, or
    /// a non-finite coordinate or elevation.
    #[error("{}: line {line}: {reason}", .path.display())]
    InvalidLine {
        /// The output file.
        path: PathBuf,
        /// Position of the line in the slice.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// An I/O operation on the file failed; the cause is the error's source.
    #[error("{}: cannot {action}", .path.display())]
    Io {
        /// The file being read or written.
        path: PathBuf,
        /// What was being done, e.g. "read" or "create a temporary file".
        action: &'static str,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The input file is not a valid file of its format: bad header, truncated data, a
    /// vertex index out of range, text where numbers belong.
    #[error("{}: invalid {format} file: {reason}", .path.display())]
    Malformed {
        /// The input file.
        path: PathBuf,
        /// The format it was read as.
        format: MeshFormat,
        /// What is wrong and where (line, element or byte offset).
        reason: String,
    },
    /// The input file is valid but uses something this crate does not read, such as
    /// faces that are not triangles.
    #[error("{}: unsupported {format} file: {feature}", .path.display())]
    Unsupported {
        /// The input file.
        path: PathBuf,
        /// The format it was read as.
        format: MeshFormat,
        /// What is not supported and where.
        feature: String,
    },
}

/// Result of this crate's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;

/// A problem found by a reader that does not know the file's path yet; turned into an
/// [`Error`] by [`Problem::at`].
#[derive(Debug)]
pub(crate) enum Problem {
    /// Reading failed.
    Io(io::Error),
    /// The data is invalid.
    Malformed(String),
    /// The data is valid but not supported.
    Unsupported(String),
}

impl Problem {
    /// A [`Problem::Malformed`] with a formatted reason.
    pub(crate) fn malformed(reason: impl fmt::Display) -> Self {
        Problem::Malformed(reason.to_string())
    }

    /// A [`Problem::Unsupported`] with a formatted description.
    pub(crate) fn unsupported(feature: impl fmt::Display) -> Self {
        Problem::Unsupported(feature.to_string())
    }

    /// Attaches the file's path and format.
    pub(crate) fn at(self, path: impl Into<PathBuf>, format: MeshFormat) -> Error {
        let path = path.into();
        match self {
            Problem::Io(source) if source.kind() == io::ErrorKind::UnexpectedEof => {
                Error::Malformed {
                    path,
                    format,
                    reason: "the file ends unexpectedly".to_owned(),
                }
            }
            Problem::Io(source) => Error::Io {
                path,
                action: "read",
                source,
            },
            Problem::Malformed(reason) => Error::Malformed {
                path,
                format,
                reason,
            },
            Problem::Unsupported(feature) => Error::Unsupported {
                path,
                format,
                feature,
            },
        }
    }
}

/// The errors of staging and renaming a file (see `tinsmith_output`) as this crate's:
/// [`Error::Io`] and [`Error::MissingDirectory`] with the same messages.
impl From<tinsmith_output::Error> for Error {
    fn from(error: tinsmith_output::Error) -> Self {
        match error {
            tinsmith_output::Error::Io {
                path,
                action,
                source,
            } => Error::Io {
                path,
                action,
                source,
            },
            tinsmith_output::Error::MissingDirectory { path, dir } => {
                Error::MissingDirectory { path, dir }
            }
            other => Error::Io {
                path: other.path().to_path_buf(),
                action: "write",
                source: io::Error::other(other),
            },
        }
    }
}

impl From<io::Error> for Problem {
    fn from(error: io::Error) -> Self {
        Problem::Io(error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_path() {
        let error = Error::MissingDirectory {
            path: PathBuf::from("/nope/out.ply"),
            dir: PathBuf::from("/nope"),
        };
        assert_eq!(
            error.to_string(),
            "/nope/out.ply: output directory /nope does not exist"
        );
        let error = Error::UnknownExtension {
            path: PathBuf::from("tin.xyz"),
        };
        let message = error.to_string();
        assert!(message.starts_with("tin.xyz: "), "{message}");
        assert!(
            message.contains(".ply") && message.contains(".xml"),
            "{message}"
        );
    }

    #[test]
    fn io_error_keeps_its_source() {
        let error = Problem::Io(io::Error::other("disk on fire")).at("a.obj", MeshFormat::Obj);
        assert_eq!(error.to_string(), "a.obj: cannot read");
        let source = std::error::Error::source(&error).map(ToString::to_string);
        assert_eq!(source.as_deref(), Some("disk on fire"));
    }

    #[test]
    fn end_of_file_is_reported_as_malformed() {
        let error = Problem::Io(io::ErrorKind::UnexpectedEof.into()).at("a.ply", MeshFormat::Ply);
        assert!(matches!(error, Error::Malformed { .. }), "{error:?}");
        assert!(error.to_string().starts_with("a.ply: invalid PLY file"));
    }
}
