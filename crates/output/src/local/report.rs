//! Reports whose room on disk is taken when the run starts.

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::atomic::{check_not_symlink, is_special_file, parent_dir, StagedFile};
use crate::error::{Error, RenameError, Result};

/// Room for a `--report` file taken before the run's outputs are committed: its temporary
/// file is made and [`REPORT_RESERVE_BYTES`] written when the run starts, so a report that
/// cannot be written (a full disk, a directory that refuses files) fails the run before any
/// output is in place, rather than after (an error exit with the outputs left behind).
/// [`ReservedReport::write`] then overwrites the bytes already taken.
#[derive(Debug)]
pub struct ReservedReport {
    path: PathBuf,
    file: Option<StagedFile>,
}

/// More than any report needs: a `mesh` report is about 1 KB, a `tiles` report about
/// 0.6 KB plus 0.3 KB per level (10 KB at 32 levels).
pub const REPORT_RESERVE_BYTES: usize = 16 * 1024;

impl ReservedReport {
    /// Creates the report's temporary file beside `path` and fills it with
    /// [`REPORT_RESERVE_BYTES`] spaces (a device or pipe is written in place, later).
    ///
    /// # Errors
    /// [`Error::Symlink`] when `path` is a symbolic link, [`Error::CannotCreate`] when the
    /// temporary file cannot be made, [`Error::WriteFailed`] when the room cannot be
    /// written.
    pub fn reserve(path: &Path) -> Result<ReservedReport> {
        if is_special_file(path) {
            return Ok(ReservedReport {
                path: path.to_path_buf(),
                file: None,
            });
        }
        check_not_symlink(path)?;
        let mut tmp = StagedFile::new(path).map_err(|source| Error::CannotCreate {
            path: path.to_path_buf(),
            dir: parent_dir(path).to_path_buf(),
            source,
        })?;
        let file = tmp.file_mut();
        file.write_all(&[b' '; REPORT_RESERVE_BYTES])
            .and_then(|()| file.flush())
            .map_err(|source| Error::WriteFailed {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(ReservedReport {
            path: path.to_path_buf(),
            file: Some(tmp),
        })
    }

    /// Writes `bytes` as the report, over the reserved room, and renames it into place.
    ///
    /// # Errors
    /// [`Error::WriteFailed`] when the bytes cannot be written, [`Error::NotRenamed`] when
    /// the finished report cannot be renamed into place.
    pub fn write(self, bytes: &[u8]) -> Result<()> {
        let failed = |source| Error::WriteFailed {
            path: self.path.clone(),
            source,
        };
        let Some(mut tmp) = self.file else {
            return std::fs::write(&self.path, bytes).map_err(failed);
        };
        let file = tmp.file_mut();
        file.seek(SeekFrom::Start(0))
            .and_then(|_| file.write_all(bytes))
            .and_then(|()| file.flush())
            .and_then(|()| file.set_len(bytes.len() as u64))
            .map_err(failed)?;
        tmp.commit().map_err(|source| Error::NotRenamed {
            path: self.path.clone(),
            source: RenameError(source),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reserved_report_holds_exactly_what_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.json");
        let reserved = ReservedReport::reserve(&path).unwrap();
        // The room is taken (in a temporary file) before anything is written.
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        reserved.write(b"{}\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"{}\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_report_that_cannot_be_reserved_fails_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("r.json");
        let err = ReservedReport::reserve(&path).err().unwrap();
        assert!(err.to_string().contains("r.json"), "{err}");
    }
}
