//! All or nothing for directories: an output directory (a tiles pyramid, a directory of
//! per-tile meshes) is built in a temporary directory renamed into place at the end.

use std::path::{Path, PathBuf};

use super::atomic::{output_parent, output_temp_dir, publish, OutputTempDir, Temp};
use crate::error::{Error, Result};
use crate::pending::{MadeDirsGuard, PendingGuard};

/// The temporary directory an output directory is built in, beside it (the target must
/// not exist, or be an empty directory), and the missing parents made for it, as
/// `mkdir -p` would. Dropped unfinished (an error), it removes the directory and the
/// parents it made while they are empty; on a signal, the pending-output registry does the
/// same (see [`crate::on_signal`]).
#[derive(Debug)]
pub struct StagedDir {
    temp: Option<OutputTempDir>,
    _pending: PendingGuard,
    /// The parent directories made here, deepest first, and their registration; `None`
    /// once the directory is in place.
    made: Option<(Vec<PathBuf>, MadeDirsGuard)>,
    /// The directory the rename lands on.
    target: PathBuf,
}

impl StagedDir {
    /// Creates the temporary directory beside `target`; its missing parents are made
    /// first when `make_parents`, else they must exist.
    ///
    /// # Errors
    /// [`Error::Occupied`] when `target` exists as anything but an empty directory;
    /// [`Error::FileInTheWay`] when an ancestor of it is a file; without `make_parents`,
    /// [`Error::MissingDirectory`] when its parent does not exist; [`Error::Io`] when the
    /// parents or the temporary directory cannot be made, or the run was interrupted.
    pub fn new(target: &Path, make_parents: bool) -> Result<StagedDir> {
        if let Some(reason) = occupied_reason(target) {
            return Err(Error::Occupied {
                path: target.to_path_buf(),
                reason,
            });
        }
        let (parent, file_in_the_way) = output_parent(target);
        if let Some(file) = file_in_the_way {
            return Err(Error::FileInTheWay {
                path: target.to_path_buf(),
                file: file.to_path_buf(),
            });
        }
        if !make_parents && !parent.is_dir() {
            return Err(Error::MissingDirectory {
                path: target.to_path_buf(),
                dir: parent.to_path_buf(),
            });
        }
        let output = |source| Error::Io {
            path: target.to_path_buf(),
            action: "create a temporary directory beside it",
            source,
        };
        let made: Vec<PathBuf> = parent
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        let guard = crate::track_made_dirs(&made);
        let temp = std::fs::create_dir_all(parent)
            .and_then(|()| output_temp_dir(parent))
            .map_err(|source| {
                remove_empty(&made);
                output(source)
            })?;
        let staging = StagedDir {
            _pending: crate::track_pending(temp.path()),
            temp: Some(temp),
            made: Some((made, guard)),
            target: target.to_path_buf(),
        };
        if crate::interrupted() {
            // The signal handler may have passed already: dropping `staging` removes it.
            return Err(output(std::io::Error::from(
                std::io::ErrorKind::Interrupted,
            )));
        }
        Ok(staging)
    }

    /// The temporary directory's path, to write the output's files into.
    pub fn path(&self) -> &Path {
        self.temp.as_ref().expect("not finished").path()
    }

    /// Renames the directory to its target; on failure it is removed (with the parents
    /// made for it).
    ///
    /// # Errors
    /// The rename's error (the target was made meanwhile and is not empty, the temporary
    /// directory was replaced by another program...).
    pub fn commit(mut self) -> std::io::Result<()> {
        let staged = self.temp.take().expect("finished once");
        publish(Temp::Dir(staged), &self.target)?;
        self.made = None;
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        drop(self.temp.take());
        if let Some((made, _)) = &self.made {
            remove_empty(made);
        }
    }
}

/// Removes directories `made` (deepest first) while they are empty.
fn remove_empty(made: &[PathBuf]) {
    for dir in made {
        if std::fs::remove_dir(dir).is_err() {
            break;
        }
    }
}

/// Why `dir` cannot take a new output directory, if it exists as anything but an empty
/// directory (a file, a link, a directory with entries): an output directory renamed
/// into place must not replace it.
fn occupied_reason(dir: &Path) -> Option<&'static str> {
    let meta = std::fs::symlink_metadata(dir).ok()?;
    if meta.is_symlink() {
        Some("is a symbolic link (give the directory it points to, or a new path)")
    } else if !meta.is_dir() {
        Some("exists and is not a directory")
    } else if std::fs::read_dir(dir).map_or(true, |mut e| e.next().is_some()) {
        Some("exists and is not an empty directory")
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_staged_directory_appears_whole_and_its_made_parents_go_on_error() {
        let root = tempfile::tempdir().expect("temp dir");
        let target = root.path().join("a/b/out");
        let staged = StagedDir::new(&target, true).expect("staged");
        std::fs::write(staged.path().join("f"), b"x").expect("write");
        assert!(!target.exists());
        staged.commit().expect("renamed");
        assert!(target.join("f").is_file());

        // Dropped unfinished: the directory and the parents made for it go.
        let other = root.path().join("c/d/out");
        let staged = StagedDir::new(&other, true).expect("staged");
        drop(staged);
        assert!(!root.path().join("c").exists());
    }

    #[test]
    fn a_staged_directory_refuses_what_it_must_not_replace() {
        let root = tempfile::tempdir().expect("temp dir");
        let full = root.path().join("full");
        std::fs::create_dir(&full).expect("mkdir");
        std::fs::write(full.join("x"), b"").expect("write");
        let err = StagedDir::new(&full, true).expect_err("occupied");
        assert!(matches!(err, Error::Occupied { .. }), "{err:?}");
        let missing = root.path().join("no/out");
        let err = StagedDir::new(&missing, false).expect_err("no parent");
        assert!(matches!(err, Error::MissingDirectory { .. }), "{err:?}");
        assert!(!root.path().join("no").exists());
        let names: Vec<_> = std::fs::read_dir(root.path())
            .expect("read")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("full")]);
    }
}
