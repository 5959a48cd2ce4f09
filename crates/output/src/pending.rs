//! Temporary files and directories on their way to becoming outputs, so that an
//! interrupted run (Ctrl-C, SIGTERM) can remove them (a temporary file is otherwise
//! removed only when its owner is dropped, which a signal's exit skips), and the one rule
//! for a signal: before the run's first output is in place the run is cancelled and every
//! output keeps its old content; from then on the run completes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static MADE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static FINISHED: AtomicBool = AtomicBool::new(false);
/// Set once an output of the run has been renamed into place (see [`place`]).
static PLACED: AtomicBool = AtomicBool::new(false);
/// Held while an output is renamed into place (see [`place`]), and for good by
/// [`on_signal`] once it cancels the run.
static PLACING: Mutex<()> = Mutex::new(());

/// What [`on_signal`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interrupt {
    /// No output of the run was in place: every registered temporary was removed (this
    /// many), and from now on [`interrupted`] is true and no output is renamed into place.
    /// Every output the run would have replaced keeps its old content; the process is to
    /// exit as interrupted.
    Cancelled {
        /// Temporaries that were registered (and are now removed).
        removed: usize,
    },
    /// An output of the run is in place already: the run goes on until the others are
    /// ([`finished`]), so the outputs are never part new and part old; the process is to
    /// exit as a success then.
    Completing,
}

/// Renames one output into place through `rename`, the commit point of a run: once an
/// output is in place, [`on_signal`] lets the run complete instead of cancelling it. A
/// signal handled before waits for nothing and the rename never starts; one handled
/// during it waits for it to end.
pub(crate) fn place<T, E>(rename: impl FnOnce() -> Result<T, E>) -> Result<T, E> {
    let placed = {
        let _guard = PLACING
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let placed = rename();
        if placed.is_ok() {
            PLACED.store(true, Ordering::SeqCst);
        }
        placed
    };
    if placed.is_ok() {
        signal_after_first_placement();
    }
    placed
}

/// For tests of the commit point: with `TINSMITH_TEST_SIGNAL_AFTER_PLACING` set to a
/// signal number, the process sends itself that signal just after its first output is
/// renamed into place, then gives the signal handler a moment to act, as if the user
/// pressed Ctrl-C at that very instant.
#[allow(unsafe_code)]
fn signal_after_first_placement() {
    static SENT: AtomicBool = AtomicBool::new(false);
    let Some(signal) = std::env::var("TINSMITH_TEST_SIGNAL_AFTER_PLACING")
        .ok()
        .and_then(|s| s.parse::<i32>().ok())
    else {
        return;
    };
    if !SENT.swap(true, Ordering::SeqCst) {
        // SAFETY: kill and getpid take no pointers.
        unsafe {
            libc::kill(libc::getpid(), signal);
        }
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
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
/// dropped: [`on_signal`] removes those that are empty then, and only those (another
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

/// What a signal handler calls on Ctrl-C, SIGTERM or SIGHUP: the one rule for every
/// command and every output. Before any output of the run is renamed into place, the run
/// is cancelled: every registered temporary file and directory is removed (and the empty
/// directories made for them), no output is renamed into place from then on, and
/// [`interrupted`] becomes true ([`Interrupt::Cancelled`]). Once one is in place, nothing
/// is removed and the run is left to put the others in place ([`Interrupt::Completing`]).
/// A rename under way is waited for first.
///
/// Writers check [`interrupted`] before each file they add, but one may be between its
/// check and its write when the flag goes up (and `create_dir_all` would make a removed
/// directory again), so the paths are removed a second time after a short pause.
pub fn on_signal() -> Interrupt {
    let guard = PLACING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if PLACED.load(Ordering::SeqCst) || finished() {
        return Interrupt::Completing;
    }
    // No output is renamed into place from now on (the process exits after this).
    std::mem::forget(guard);
    INTERRUPTED.store(true, Ordering::SeqCst);
    // Read again for the second pass: a path registered meanwhile (its owner was
    // between creating it and registering it) is removed too.
    let paths = || match PENDING.lock() {
        Ok(pending) => pending.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    let removed = paths().len();
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
    Interrupt::Cancelled { removed }
}

/// Whether [`on_signal`] cancelled the run: the work still going on may fail on the files it
/// removed, and should leave the process to the signal handler's exit.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_registered_until_their_guard_drops() {
        // Inspects the registry rather than cancelling through `on_signal`, which would
        // flag the whole test process as interrupted and remove other tests' temporaries.
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

    #[test]
    fn a_signal_after_the_first_output_is_in_place_lets_the_run_complete() {
        use std::io::Write as _;
        let dir = tempfile::tempdir().expect("temp dir");
        let mesh = dir.path().join("mesh.ply");
        let report = dir.path().join("report.json");
        std::fs::write(&report, b"old").expect("seed");
        crate::write_atomically(&mesh, |w| w.write_all(b"new")).expect("placed");
        // The run's other output, staged but not yet in place, when the signal comes.
        let staged = crate::StagedFile::new(&report).expect("staged");
        assert_eq!(on_signal(), Interrupt::Completing);
        // Nothing was removed and the run may go on: the report still goes in place.
        assert!(!interrupted());
        assert!(staged.path().exists());
        std::fs::write(staged.path(), b"new").expect("write");
        staged.commit().expect("renamed after the signal");
        assert_eq!(std::fs::read(&report).expect("read"), b"new");
    }
}
