//! Temporary files and directories on their way to becoming outputs, so that an
//! interrupted run (Ctrl-C, SIGTERM) can remove them: a temporary file is otherwise removed
//! only when its owner is dropped, which a signal's exit skips.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static MADE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static FINISHED: AtomicBool = AtomicBool::new(false);
/// Held while files that belong together are renamed into place (see [`commit_together`]),
/// and for good by [`remove_pending`].
static COMMITTING: Mutex<()> = Mutex::new(());

/// Runs `commit` (renames that must all happen or none, such as a mesh and its `.prj`)
/// so that [`remove_pending`], on a signal, waits for it to end and then lets no other
/// commit start: an interrupt never leaves half of such a pair in place.
pub(crate) fn commit_together<T>(commit: impl FnOnce() -> T) -> T {
    let _guard = COMMITTING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    commit()
}

/// Records that every output of the run is complete and in place: a signal from now on
/// (the process tearing its memory down) interrupts nothing.
pub fn mark_finished() {
    FINISHED.store(true, Ordering::SeqCst);
}

/// Whether [`mark_finished`] was called.
pub fn finished() -> bool {
    FINISHED.load(Ordering::SeqCst)
}

/// Registers `path` (a temporary file or directory) until the returned guard is dropped.
pub fn track_pending(path: &Path) -> PendingGuard {
    if let Ok(mut pending) = PENDING.lock() {
        pending.push(path.to_path_buf());
    }
    PendingGuard(path.to_path_buf())
}

/// Unregisters its path when dropped (the owner has renamed or removed it by then).
#[derive(Debug)]
pub struct PendingGuard(PathBuf);

impl Drop for PendingGuard {
    fn drop(&mut self) {
        if let Ok(mut pending) = PENDING.lock() {
            if let Some(i) = pending.iter().rposition(|p| p == &self.0) {
                pending.swap_remove(i);
            }
        }
    }
}

/// Registers directories made for an output (deepest first) until the returned guard is
/// dropped: [`remove_pending`] removes those that are empty then, and only those (another
/// program may have put files there meanwhile).
pub fn track_made_dirs(dirs: &[PathBuf]) -> MadeDirsGuard {
    if let Ok(mut made) = MADE.lock() {
        made.extend_from_slice(dirs);
    }
    MadeDirsGuard(dirs.to_vec())
}

/// Unregisters its directories when dropped.
#[derive(Debug)]
pub struct MadeDirsGuard(Vec<PathBuf>);

impl Drop for MadeDirsGuard {
    fn drop(&mut self) {
        if let Ok(mut made) = MADE.lock() {
            for dir in &self.0 {
                if let Some(i) = made.iter().rposition(|p| p == dir) {
                    made.remove(i);
                }
            }
        }
    }
}

/// Removes every registered temporary file and directory (for a signal handler, just
/// before the process exits), and from then on [`interrupted`] is true; returns how many
/// were registered. Paths that are gone already are skipped. It first waits for a
/// rename of files that belong together to end, and from then on no such rename starts.
///
/// Writers check [`interrupted`] before each file they add, but one may be between its
/// check and its write when the flag goes up (and `create_dir_all` would make a removed
/// directory again), so the paths are removed a second time after a short pause.
pub fn remove_pending() -> usize {
    // Wait for renames under way to end, and keep any other from starting (the process
    // exits after this).
    std::mem::forget(
        COMMITTING
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner()),
    );
    INTERRUPTED.store(true, Ordering::SeqCst);
    // Read again for the second pass: a path registered meanwhile (its owner was
    // between creating it and registering it) is removed too.
    let paths = || match PENDING.lock() {
        Ok(pending) => pending.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    let count = paths().len();
    let remove_all = || {
        for path in &paths() {
            if path.is_dir() {
                let _ = std::fs::remove_dir_all(path);
            } else {
                let _ = std::fs::remove_file(path);
            }
        }
    };
    remove_all();
    std::thread::sleep(std::time::Duration::from_millis(150));
    remove_all();
    let made = match MADE.lock() {
        Ok(made) => made.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    for dir in &made {
        let _ = std::fs::remove_dir(dir);
    }
    count
}

/// Whether [`remove_pending`] has run: the work still going on may fail on the files it
/// removed, and should leave the process to the signal handler's exit.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_registered_until_their_guard_drops() {
        // Inspects the registry rather than calling `remove_pending`, which would flag the
        // whole test process as interrupted and remove other tests' temporary files.
        let dir = tempfile::tempdir().expect("temp dir");
        let (a, b) = (dir.path().join("a.tmp"), dir.path().join("b.tmp"));
        let registered = |p: &Path| PENDING.lock().unwrap().iter().any(|q| q == p);
        let guard_a = track_pending(&a);
        {
            let _guard_b = track_pending(&b);
            assert!(registered(&b));
        }
        assert!(registered(&a) && !registered(&b));
        drop(guard_a);
        assert!(!registered(&a));
        let made = [dir.path().join("m")];
        let guard = track_made_dirs(&made);
        assert!(MADE.lock().unwrap().contains(&made[0]));
        drop(guard);
        assert!(!MADE.lock().unwrap().contains(&made[0]));
    }
}
