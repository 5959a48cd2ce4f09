//! Where and how a run's outputs land on disk: every mesh, sidecar, contour file, report,
//! tiles pyramid and per-tile directory is staged beside its target and published whole.
//! This crate knows nothing about formats; the format writers hand it bytes.
//!
//! # Guarantees
//! - **Complete outputs or the old ones.** An output is written to a temporary
//!   (`.tinsmith-*.tmp`, a file or a directory) next to its target and renamed into place
//!   only when complete ([`write_atomically`], [`write_bytes_atomically`], [`StagedDir`],
//!   and [`StagedFile`] for a file another library writes, such as an SQLite database);
//!   files a run only reads back itself go in a [`ScratchDir`];
//!   a sidecar (a mesh's `.prj`) is staged with its file and renamed just before it
//!   ([`write_atomically_with_sidecar`]). A run that fails leaves the previous output at
//!   the target untouched (or none); a file it replaces keeps its permissions; an output
//!   at a symbolic link is refused, a file as a directory (the link's target may be
//!   anywhere); a device or pipe (even through a link, as `/dev/stdout`) is written in
//!   place.
//! - **One rule for a signal.** The first output renamed into place is the run's commit
//!   point ([`on_signal`]): a signal before it cancels the run, removing every pending
//!   temporary (the work still running sees [`interrupted`]), so every output keeps its
//!   old content; a signal after it lets the run put its other outputs in place, so the
//!   run completes. The outputs of a run are never part new, part old.
//! - **No temporaries left behind.** A temporary is removed when its owner is dropped
//!   (an error) or when a signal cancels the run; one left by a run that was killed
//!   outright (SIGKILL, the out-of-memory killer) is removed by the next run that writes
//!   in the same directory ([`take_removed_stale`] says which).
//! - **Early refusal.** [`check_writable_target`] and its kin refuse, before long work,
//!   targets the run could not replace or must not (the input itself, a read-only file,
//!   another output of the same run), and [`ReservedReport`] takes a report's room on disk
//!   when the run starts.
//!
//! Outputs go to the local file system (the `local` module); the registry of pending
//! temporaries and the commit point ([`on_signal`]) are process-wide.

mod error;
mod local;
mod pending;

pub use error::{Error, RenameError, Result};
pub use local::atomic::{
    check_not_symlink, is_special_file, resolve_output, unnamed_temp_file, write_atomically,
    write_atomically_with_sidecar, write_bytes_atomically, StagedFile,
};
pub use local::check::{check_distinct, check_not_inside, check_writable_target};
pub use local::report::{ReservedReport, REPORT_RESERVE_BYTES};
pub use local::scratch::ScratchDir;
pub use local::staging::StagedDir;
pub use local::stale::{take_removed_stale, RemovedTemp};
pub use pending::{finished, interrupted, mark_finished, on_signal, Interrupt};

pub(crate) use pending::{track_made_dirs, track_pending};
