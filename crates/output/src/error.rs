//! The error type of output handling: one enum, every variant names the path it is about.

use std::io;
use std::path::{Path, PathBuf};

/// What can go wrong while checking, staging or publishing an output.
///
/// The checks made before long work ([`crate::check_writable_target`] and its kin) refuse
/// a target with one of the variants from [`Error::EndsWithSlash`] to
/// [`Error::InsideOutputDir`]; staging and publishing fail with [`Error::Io`] (the cause is
/// the source), [`Error::MissingDirectory`] or, for a staged directory,
/// [`Error::Occupied`] and [`Error::FileInTheWay`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An I/O operation on the output failed; the cause is the error's source.
    #[error("{}: cannot {action}", .path.display())]
    Io {
        /// The output being written.
        path: PathBuf,
        /// What was being done, e.g. "write" or "create a temporary file".
        action: &'static str,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// The directory the output should be created in does not exist.
    #[error("{}: output directory {} does not exist", .path.display(), .dir.display())]
    MissingDirectory {
        /// The output.
        path: PathBuf,
        /// Its parent directory, which is missing.
        dir: PathBuf,
    },
    /// The output path ends with '/', which names a directory.
    #[error(
        "{}: ends with '/', which names a directory, not an output file",
        .path.display()
    )]
    EndsWithSlash {
        /// The output as given.
        path: PathBuf,
    },
    /// The output path is a symbolic link that loops (or a chain of too many).
    #[error(
        "{}: is a symbolic link that loops (or a chain of too many); point it at a file \
         or remove it",
        .path.display()
    )]
    SymlinkLoop {
        /// The output as given.
        path: PathBuf,
    },
    /// The output path is a symbolic link: outputs are not written through links, files
    /// and directories alike (the link's target may be anywhere).
    #[error(
        "{}: is a symbolic link, and outputs are not written through links (give the \
         path it points to, or a new one)",
        .path.display()
    )]
    Symlink {
        /// The output as given.
        path: PathBuf,
    },
    /// The output's name is too long for its file system.
    #[error(
        "{}: the name is too long for its file system; choose a shorter one",
        .path.display()
    )]
    NameTooLong {
        /// The output as given.
        path: PathBuf,
    },
    /// The output is the input file itself (a raster, points or a TIN).
    #[error(
        "{}: is the input file {}; writing there would destroy it",
        .path.display(),
        .input.display()
    )]
    IsInput {
        /// The output as given.
        path: PathBuf,
        /// The input raster.
        input: PathBuf,
    },
    /// The output is one of the files the input raster is read from.
    #[error(
        "{}: is a file the input raster {} is read from (GDAL lists it among the \
         input's files); writing there would change or destroy the input",
        .path.display(),
        .input.display()
    )]
    ReadByInput {
        /// The output as given.
        path: PathBuf,
        /// The input raster.
        input: PathBuf,
    },
    /// An ancestor of the output's directory is a file.
    #[error("{}: {} is a file, not a directory", .path.display(), .file.display())]
    FileInTheWay {
        /// The output as given.
        path: PathBuf,
        /// The file where a directory should be.
        file: PathBuf,
    },
    /// The output is a directory where a file is to be written.
    #[error("{}: is a directory, not an output file", .path.display())]
    IsDirectory {
        /// The output as given.
        path: PathBuf,
    },
    /// The output exists and is read-only: it is not replaced behind its owner's back.
    #[error(
        "{}: exists and is read-only; make it writable (chmod u+w) or remove it to \
         replace it",
        .path.display()
    )]
    ReadOnly {
        /// The output as given.
        path: PathBuf,
    },
    /// The output belongs to another user in a sticky directory (as `/tmp`).
    #[error(
        "{}: belongs to another user in a directory where only a file's owner may \
         replace it (sticky bit, as in /tmp); choose another name",
        .path.display()
    )]
    StickyOwner {
        /// The output as given.
        path: PathBuf,
    },
    /// Two files of one run are the same file: one would overwrite the other.
    #[error(
        "{}: is also {what} {}; one would overwrite the other",
        .path.display(),
        .other.display()
    )]
    SameFile {
        /// The file that would overwrite the other.
        path: PathBuf,
        /// The file it is the same as.
        other: PathBuf,
        /// What `other` is, e.g. "the output".
        what: String,
    },
    /// A report would be written inside (or over) a directory the run fills.
    #[error(
        "{}: is {what} {} or inside it; write the report elsewhere",
        .path.display(),
        .dir.display()
    )]
    InsideOutputDir {
        /// The report.
        path: PathBuf,
        /// The directory the run fills.
        dir: PathBuf,
        /// What the directory is, e.g. "the pyramid directory".
        what: String,
    },
    /// A report's temporary file cannot be created in its directory.
    #[error("{}: cannot create a file in {}", .path.display(), .dir.display())]
    CannotCreate {
        /// The report as given.
        path: PathBuf,
        /// The directory the temporary file was to be made in.
        dir: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// Writing a report's bytes failed.
    #[error("{}: write failed", .path.display())]
    WriteFailed {
        /// The report as given.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: io::Error,
    },
    /// A report, complete, could not be renamed into place.
    #[error("{}: cannot write", .path.display())]
    NotRenamed {
        /// The report as given.
        path: PathBuf,
        /// The rename's error.
        #[source]
        source: RenameError,
    },
    /// A directory to be staged exists as something a new directory must not replace:
    /// a file, a link, or a directory with entries.
    #[error("{}: {reason}", .path.display())]
    Occupied {
        /// The directory as given.
        path: PathBuf,
        /// Why it cannot be replaced.
        reason: &'static str,
    },
}

impl Error {
    /// The path the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Error::Io { path, .. }
            | Error::MissingDirectory { path, .. }
            | Error::EndsWithSlash { path }
            | Error::SymlinkLoop { path }
            | Error::Symlink { path }
            | Error::NameTooLong { path }
            | Error::IsInput { path, .. }
            | Error::ReadByInput { path, .. }
            | Error::FileInTheWay { path, .. }
            | Error::IsDirectory { path }
            | Error::ReadOnly { path }
            | Error::StickyOwner { path }
            | Error::SameFile { path, .. }
            | Error::InsideOutputDir { path, .. }
            | Error::CannotCreate { path, .. }
            | Error::WriteFailed { path, .. }
            | Error::NotRenamed { path, .. }
            | Error::Occupied { path, .. } => path,
        }
    }
}

/// Result of this crate's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;

/// A finished temporary file that could not be renamed over its target.
#[derive(Debug, thiserror::Error)]
#[error("failed to persist temporary file: {0}")]
pub struct RenameError(#[source] pub io::Error);
