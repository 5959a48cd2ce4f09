//! All or nothing: the pyramid is built in a temporary directory renamed into place at the
//! end.

use std::path::{Path, PathBuf};

use super::{TerrainError, TerrainResult};

/// The temporary directory a pyramid is built in, beside `out_dir` (which must not exist,
/// or be an empty directory), and the missing parents made for it, as `mkdir -p` would.
/// Dropped unfinished (an error), it removes the directory and the parents it made while
/// they are empty; on a signal, the pending-output registry does the same.
pub(super) struct Staging {
    temp: Option<tinsmith_export::OutputTempDir>,
    _pending: tinsmith_export::PendingGuard,
    /// The parent directories made here, deepest first, and their registration; `None`
    /// once the pyramid is in place.
    made: Option<(Vec<PathBuf>, tinsmith_export::MadeDirsGuard)>,
}

impl Staging {
    pub(super) fn new(out_dir: &Path) -> TerrainResult<Staging> {
        let refuse = |reason: String| {
            TerrainError::Options(format!("output {}: {reason}", out_dir.display()))
        };
        if let Some(reason) = crate::per_tile::occupied_reason(out_dir) {
            return Err(refuse(format!(
                "{reason}; give a new directory (the pyramid is written whole, never mixed \
                 with other files)"
            )));
        }
        let (parent, file_in_the_way) = tinsmith_export::output_parent(out_dir);
        if let Some(file) = file_in_the_way {
            return Err(refuse(format!(
                "{} is a file, so no directory can be made there",
                file.display()
            )));
        }
        let output = |source| TerrainError::Output {
            path: out_dir.to_path_buf(),
            source,
        };
        let made: Vec<PathBuf> = parent
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        let guard = tinsmith_export::track_made_dirs(&made);
        let temp = std::fs::create_dir_all(parent)
            .and_then(|()| tinsmith_export::output_temp_dir(parent))
            .map_err(|source| {
                remove_empty(&made);
                output(source)
            })?;
        let staging = Staging {
            _pending: tinsmith_export::track_pending(temp.path()),
            temp: Some(temp),
            made: Some((made, guard)),
        };
        if tinsmith_export::interrupted() {
            // The signal handler may have passed already: dropping `staging` removes it.
            return Err(output(std::io::Error::from(
                std::io::ErrorKind::Interrupted,
            )));
        }
        Ok(staging)
    }

    pub(super) fn path(&self) -> &Path {
        self.temp.as_ref().expect("not finished").path()
    }

    /// Renames the directory to `out_dir`; on failure it is removed (with the parents
    /// made for it, when dropped).
    pub(super) fn finish(&mut self, out_dir: &Path) -> TerrainResult<()> {
        let staged = self.temp.take().expect("finished once");
        match staged.rename_into_place(out_dir) {
            Ok(()) => {
                self.made = None;
                Ok(())
            }
            Err(source) => Err(TerrainError::Output {
                path: out_dir.to_path_buf(),
                source,
            }),
        }
    }
}

impl Drop for Staging {
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

pub(super) fn write_atomic(path: &Path, bytes: &[u8]) -> TerrainResult<()> {
    let output = |source| TerrainError::Output {
        path: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut file = tinsmith_export::output_temp_file(dir).map_err(output)?;
    std::io::Write::write_all(&mut file, bytes).map_err(output)?;
    file.persist(path).map_err(|e| output(e.error))?;
    Ok(())
}
