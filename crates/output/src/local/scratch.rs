//! A run's private working directory: read back by the run, never published.

use std::io;
use std::path::Path;

use crate::pending::PendingGuard;

/// A temporary directory in the system's temporary directory (`TMPDIR`), named
/// `.tinsmith-scratch-*`, for files a run writes and reads back itself (a raster resampled
/// onto another's grid, for example). Removed with everything in it when dropped, and by
/// [`crate::on_signal`] when a signal cancels the run.
#[derive(Debug)]
pub struct ScratchDir {
    dir: tempfile::TempDir,
    _pending: PendingGuard,
}

impl ScratchDir {
    /// Makes a new, empty scratch directory.
    ///
    /// # Errors
    /// When the system's temporary directory cannot hold a new directory.
    pub fn new() -> io::Result<ScratchDir> {
        let dir = tempfile::Builder::new()
            .prefix(".tinsmith-scratch-")
            .tempdir()?;
        let pending = crate::track_pending(dir.path());
        Ok(ScratchDir {
            dir,
            _pending: pending,
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }
}
