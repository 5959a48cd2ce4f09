//! Temporary outputs left behind by runs that were killed (SIGKILL, the out-of-memory
//! killer, a power cut), found and removed by the next run that writes in the same
//! directory.
//!
//! Every `.tinsmith-*.tmp` file or directory a run creates ([`crate::output_temp_file`],
//! [`crate::output_temp_dir`]) is locked (`flock`) by that run for as long as it exists,
//! and the kernel drops the lock when the process ends, however it ends. So a temporary
//! whose lock can be taken belongs to no live run. Before a run's first temporary in a
//! directory, the others there are swept: those that can be locked and were last modified
//! more than [`MIN_STALE_AGE`] ago (the time between a temporary's creation and its lock
//! is not atomic) are removed and recorded for [`take_removed_stale`].

use std::collections::HashSet;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, SystemTime};

/// Age (since the last modification) below which an unlocked temporary is left alone: it
/// may have been created by a live run that has not locked it yet.
pub const MIN_STALE_AGE: Duration = Duration::from_secs(60);

/// Directories already swept by this process.
static SWEPT: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);
/// What the sweeps removed, for [`take_removed_stale`].
static REMOVED: Mutex<Vec<RemovedTemp>> = Mutex::new(Vec::new());

/// A stale temporary output removed by a sweep.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RemovedTemp {
    /// Where it was.
    pub path: PathBuf,
    /// Its size in bytes (a directory's files summed).
    pub bytes: u64,
}

/// The stale temporaries removed so far (each returned once).
pub fn take_removed_stale() -> Vec<RemovedTemp> {
    let mut removed = REMOVED.lock().unwrap_or_else(|p| p.into_inner());
    std::mem::take(&mut *removed)
}

/// Whether `name` is the name of one of our temporaries: `.tinsmith-*.tmp`.
fn is_temp_name(name: &str) -> bool {
    name.len() > ".tinsmith-.tmp".len() && name.starts_with(".tinsmith-") && name.ends_with(".tmp")
}

/// Sweeps `dir` once per process (see the module docs). Best effort: anything that cannot
/// be read, locked or removed (another user's file in a shared directory) is left.
pub(crate) fn sweep_once(dir: &Path) {
    // Keyed by the canonical path, so that the sweep comes before this process's own
    // first temporary there, however the directory is spelled: where locks are POSIX
    // record locks (NFS), a process's own locks do not stop it.
    let key = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    {
        let mut swept = SWEPT.lock().unwrap_or_else(|p| p.into_inner());
        if !swept.get_or_insert_with(HashSet::new).insert(key) {
            return;
        }
    }
    let removed = sweep(dir, SystemTime::now());
    if !removed.is_empty() {
        REMOVED
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .extend(removed);
    }
}

/// Removes the stale temporaries in `dir` as of `now`; returns them.
fn sweep(dir: &Path, now: SystemTime) -> Vec<RemovedTemp> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        if !name.to_str().is_some_and(is_temp_name) {
            continue;
        }
        let path = entry.path();
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        let old_enough = meta
            .modified()
            .ok()
            .and_then(|m| now.duration_since(m).ok())
            .is_some_and(|age| age >= MIN_STALE_AGE);
        if !old_enough || !(meta.is_file() || meta.is_dir()) {
            continue;
        }
        // Opening read-only is enough to take an flock, on files and directories alike.
        let Ok(handle) = File::open(&path) else {
            continue;
        };
        if handle.try_lock().is_err() {
            continue; // A live run holds it (or locks are not supported here).
        }
        let (bytes, gone) = if meta.is_dir() {
            (dir_bytes(&path), std::fs::remove_dir_all(&path).is_ok())
        } else {
            (meta.len(), std::fs::remove_file(&path).is_ok())
        };
        if gone {
            removed.push(RemovedTemp { path, bytes });
        }
    }
    removed.sort_by(|a, b| a.path.cmp(&b.path));
    removed
}

/// The summed size of the files under `dir` (symbolic links not followed).
fn dir_bytes(dir: &Path) -> u64 {
    let mut total = 0;
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            match entry.metadata() {
                Ok(m) if m.is_dir() => stack.push(entry.path()),
                Ok(m) => total += m.len(),
                Err(_) => {}
            }
        }
    }
    total
}

/// Locks `handle` (a temporary's file or directory) for as long as it stays open: see the
/// module docs. Best effort: a file system without locks leaves it unlocked (and its
/// temporaries are then taken for a live run's by no one, but removed only when stale).
pub(crate) fn hold(handle: &File) {
    let _ = handle.lock();
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn age(path: &Path, by: Duration) {
        let when = SystemTime::now() - by;
        File::open(path)
            .and_then(|f| f.set_modified(when))
            .expect("set mtime");
    }

    #[test]
    fn temp_names() {
        assert!(is_temp_name(".tinsmith-a1B2c3.tmp"));
        assert!(!is_temp_name(".tinsmith-.tmp"));
        assert!(!is_temp_name("tinsmith-a1B2c3.tmp"));
        assert!(!is_temp_name(".tinsmith-a1B2c3.tmp.ply"));
        assert!(!is_temp_name("mesh.ply"));
    }

    #[test]
    fn sweeps_old_unlocked_temporaries_only() {
        let dir = tempfile::tempdir().expect("temp dir");
        let d = dir.path();
        let old_file = d.join(".tinsmith-old.tmp");
        std::fs::write(&old_file, b"12345").expect("write");
        age(&old_file, Duration::from_secs(3600));
        let old_dir = d.join(".tinsmith-olddir.tmp");
        std::fs::create_dir_all(old_dir.join("0/1")).expect("mkdir");
        std::fs::write(old_dir.join("0/1/2.terrain"), b"abc").expect("write");
        age(&old_dir, Duration::from_secs(3600));
        let young = d.join(".tinsmith-young.tmp");
        std::fs::write(&young, b"x").expect("write");
        let locked = d.join(".tinsmith-locked.tmp");
        std::fs::write(&locked, b"x").expect("write");
        age(&locked, Duration::from_secs(3600));
        // Another open file description, as another process would have.
        let holder = File::open(&locked).expect("open");
        holder.lock().expect("lock");
        let other = d.join("mesh.ply");
        std::fs::write(&other, b"x").expect("write");
        age(&other, Duration::from_secs(3600));

        let removed = sweep(d, SystemTime::now());
        assert_eq!(
            removed,
            vec![
                RemovedTemp {
                    path: old_file.clone(),
                    bytes: 5
                },
                RemovedTemp {
                    path: old_dir.clone(),
                    bytes: 3
                },
            ]
        );
        assert!(!old_file.exists() && !old_dir.exists());
        assert!(young.exists() && locked.exists() && other.exists());
        drop(holder);
        let later = SystemTime::now() + MIN_STALE_AGE;
        let removed = sweep(d, later);
        let paths: Vec<_> = removed.into_iter().map(|r| r.path).collect();
        assert_eq!(paths, vec![locked.clone(), young.clone()]);
        assert!(other.exists());
    }
}
