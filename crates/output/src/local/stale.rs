//! Temporary outputs left behind by runs that were killed (SIGKILL, the out-of-memory
//! killer, a power cut), found and removed by the next run that writes in the same
//! directory.
//!
//! Every `.tinsmith-*.tmp` file or directory a run creates ([`crate::StagedFile`],
//! [`crate::StagedDir`]) is locked (`flock`) by that run for as long as it exists,
//! and the kernel drops the lock when the process ends, however it ends. So a temporary
//! whose lock can be taken belongs to no live run. Before a run's first temporary in a
//! directory, the others there are swept: those that can be locked and were last modified
//! more than [`MIN_STALE_AGE`] ago (the time between a temporary's creation and its lock
//! is not atomic) are removed and recorded for [`take_removed_stale`]. Only the user's own
//! are touched, and a directory with another file system mounted inside is left whole.
//!
//! Where locks do not work as on a local file system (NFS emulates `flock` with record
//! locks, which a read-only handle cannot take), nothing can be locked by the sweep, so
//! nothing is removed there. Where a lock is local to one host but the directory is shared
//! (NFS with `local_lock=flock`), a run on another host may take a live run's staging
//! directory for stale: that run then fails ([`crate::StagedDir::commit`]
//! checks its directory is still the one it made) rather than publish a partial pyramid.

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
    /// Its size in bytes (a directory's files summed) before the removal.
    pub bytes: u64,
    /// Whether all of it went (a directory's removal can stop partway, on a file the
    /// user may not remove).
    pub complete: bool,
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
        if let Some(r) = remove_if_stale(&path, now) {
            removed.push(r);
        }
    }
    removed.sort_by(|a, b| a.path.cmp(&b.path));
    removed
}

/// Removes the temporary at `path` if it is stale (see the module docs).
fn remove_if_stale(path: &Path, now: SystemTime) -> Option<RemovedTemp> {
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    let meta = std::fs::symlink_metadata(path).ok()?;
    let old_enough = meta
        .modified()
        .ok()
        .and_then(|m| now.duration_since(m).ok())
        .is_some_and(|age| age >= MIN_STALE_AGE);
    let own = effective_uid() == Some(meta.uid());
    if !old_enough || !own || !(meta.is_file() || meta.is_dir()) {
        return None;
    }
    // Read-only is enough to take an flock, on files and directories alike. Not following
    // a link and not waiting on a FIFO, in case the name changed since it was looked at;
    // the handle must be the entry looked at.
    let handle = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .ok()?;
    let opened = handle.metadata().ok()?;
    if (opened.dev(), opened.ino()) != (meta.dev(), meta.ino()) {
        return None;
    }
    if handle.try_lock().is_err() {
        return None; // A live run holds it (or locks do not work here).
    }
    if meta.is_dir() {
        // A file system mounted inside would be emptied too: leave such a directory.
        let bytes = dir_bytes(path, meta.dev())?;
        let complete = std::fs::remove_dir_all(path).is_ok();
        Some(RemovedTemp {
            path: path.to_path_buf(),
            bytes,
            complete,
        })
    } else {
        std::fs::remove_file(path).ok()?;
        Some(RemovedTemp {
            path: path.to_path_buf(),
            bytes: meta.len(),
            complete: true,
        })
    }
}

/// The process's effective user id, as the owner of `/proc/self` (Linux gives a process's
/// directory there its effective ids); `None` without `/proc`, and nothing is swept then.
fn effective_uid() -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata("/proc/self").ok().map(|m| m.uid())
}

/// The summed size of the files under `dir` (symbolic links not followed), or `None` when
/// some directory inside is on another device than `dev` (a mount point).
fn dir_bytes(dir: &Path, dev: u64) -> Option<u64> {
    use std::os::unix::fs::MetadataExt;
    let mut total = 0;
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for entry in entries.flatten() {
            match entry.metadata() {
                Ok(m) if m.is_dir() && m.dev() != dev => return None,
                Ok(m) if m.is_dir() => stack.push(entry.path()),
                Ok(m) => total += m.len(),
                Err(_) => {}
            }
        }
    }
    Some(total)
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
    fn a_directory_with_another_device_inside_is_not_sized_for_removal() {
        use std::os::unix::fs::MetadataExt;
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(dir.path().join("sub")).expect("mkdir");
        std::fs::write(dir.path().join("sub/f"), b"1234").expect("write");
        let dev = std::fs::metadata(dir.path()).expect("stat").dev();
        assert_eq!(dir_bytes(dir.path(), dev), Some(4));
        // As if `sub` were a mount point: its device differs from the top's.
        assert_eq!(dir_bytes(dir.path(), dev.wrapping_add(1)), None);
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
                    bytes: 5,
                    complete: true,
                },
                RemovedTemp {
                    path: old_dir.clone(),
                    bytes: 3,
                    complete: true,
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
