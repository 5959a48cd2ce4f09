//! All-or-nothing file output: write a temporary file next to the target, then rename it.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::pending::PendingGuard;

/// Size of the write buffer.
const BUFFER_SIZE: usize = 1 << 16;

/// Writes `path` through `write`, atomically.
///
/// The data goes to a temporary file (`.tinsmith-*.tmp`) in `path`'s directory, is flushed
/// and synced, then renamed over `path`. If anything fails, the temporary file is removed
/// and `path` is left as it was: absent, or holding its previous content.
///
/// # Errors
/// [`Error::MissingDirectory`] when `path`'s directory does not exist; [`Error::Io`] when
/// the temporary file cannot be made, `write` or the rename fails.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> io::Result<()>,
{
    stage(path, write)?.commit()
}

/// Writes `path` through `write` and, when given, a small `sidecar` file (path, bytes)
/// beside it, both atomically: nothing is renamed into place before both are complete.
///
/// The sidecar is renamed first, then the main file. If the main file's rename fails, the
/// new sidecar is removed again (a previous sidecar at that path is then gone too; the
/// main file keeps its previous content). Output to a device or pipe (`/dev/null`, a
/// FIFO) gets no sidecar: there is no file for it to describe.
///
/// # Errors
/// As [`write_atomically`].
pub fn write_atomically_with_sidecar<F>(
    path: &Path,
    write: F,
    sidecar: Option<(&Path, &[u8])>,
) -> Result<()>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> io::Result<()>,
{
    let sidecar = sidecar.filter(|_| !is_special_file(path));
    let main = stage(path, write)?;
    let Some((sidecar_path, bytes)) = sidecar else {
        return main.commit();
    };
    let side = stage(sidecar_path, |w| w.write_all(bytes))?;
    // Once the sidecar is in place, a signal lets the run complete (see
    // `crate::on_signal`): the main file follows it.
    side.commit()?;
    main.commit().inspect_err(|_| {
        let _ = std::fs::remove_file(sidecar_path);
    })
}

/// Writes `bytes` to `path` through a temporary file renamed over it: for the many files
/// of a [`crate::StagedDir`], which is itself renamed into place and removed whole on
/// error or signal, so the file is neither synced nor registered as pending, and its
/// target is new (no permissions to keep).
///
/// # Errors
/// The I/O error of creating, writing or renaming the temporary file.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut temp = output_temp_file(parent_dir(path))?;
    temp.write_all(bytes)?;
    temp.persist(path).map(drop).map_err(|e| e.error)
}

/// A complete, synced temporary file waiting to be renamed over its target, or output
/// already written in place to a device or pipe.
struct Staged {
    /// `None` when the output went straight to a device or pipe.
    file: Option<StagedFile>,
    /// The path asked for, for messages.
    path: PathBuf,
}

impl Staged {
    /// Renames the temporary file over the target.
    fn commit(self) -> Result<()> {
        let Some(file) = self.file else {
            return Ok(());
        };
        file.commit().map_err(|source| Error::Io {
            path: self.path,
            action: "move the finished temporary file into place",
            source,
        })
    }
}

/// A temporary file `.tinsmith-*.tmp` beside the file it is to replace, registered for
/// removal on a signal (see [`crate::on_signal`]) until [`StagedFile::commit`] renames
/// it over its target; dropped without that, it is removed.
#[derive(Debug)]
pub struct StagedFile {
    temp: tempfile::NamedTempFile,
    /// Keeps the temporary file registered for removal on a signal until it is renamed.
    _pending: PendingGuard,
    /// The file the rename lands on.
    target: PathBuf,
}

impl StagedFile {
    /// Creates the temporary file in the directory of `target` (the file the rename is
    /// to land on: a symbolic link there would be replaced, not followed).
    ///
    /// # Errors
    /// The I/O error of creating the temporary file.
    pub fn new(target: &Path) -> io::Result<StagedFile> {
        let temp = output_temp_file(parent_dir(target))?;
        Ok(StagedFile {
            _pending: crate::track_pending(temp.path()),
            temp,
            target: target.to_path_buf(),
        })
    }

    /// The temporary file's path (`.tinsmith-*.tmp` beside the target), for a library that
    /// opens the file itself.
    pub fn path(&self) -> &Path {
        self.temp.path()
    }

    /// The temporary file.
    pub fn file(&self) -> &File {
        self.temp.as_file()
    }

    /// The temporary file, to write to.
    pub fn file_mut(&mut self) -> &mut File {
        self.temp.as_file_mut()
    }

    /// Renames the temporary file over its target, which keeps its permissions when it
    /// is a file already (a private mesh stays private). On failure the temporary file is
    /// removed and the target left as it was.
    ///
    /// # Errors
    /// The rename's error.
    pub fn commit(self) -> io::Result<()> {
        keep_permissions(self.temp.path(), &self.target);
        publish(Temp::File(self.temp), &self.target)
    }
}

/// A locked temporary, file or directory, as [`publish`] takes it.
pub(crate) enum Temp {
    File(tempfile::NamedTempFile),
    Dir(OutputTempDir),
}

/// Renames a staged temporary over `target`: the one step by which every output (a file,
/// its sidecar, a whole directory) appears in place, and the run's commit point (see
/// [`crate::on_signal`]). The temporary stays locked until the rename is done (a sweep
/// cannot take it between); on failure it is removed.
pub(crate) fn publish(temp: Temp, target: &Path) -> io::Result<()> {
    crate::pending::place(|| match temp {
        Temp::File(temp) => temp.persist(target).map(drop).map_err(|error| error.error),
        Temp::Dir(dir) => dir.rename_into_place(target),
    })
}

/// Gives the temporary file at `temp` the permissions of the regular file at `target` it
/// is about to replace, so that replacing a file keeps its mode (a private 0600 mesh stays
/// private); nothing when `target` does not exist yet. Best effort: a failure leaves the
/// new file's default mode.
pub(crate) fn keep_permissions(temp: &Path, target: &Path) {
    if let Ok(meta) = std::fs::metadata(target) {
        if meta.is_file() {
            let _ = std::fs::set_permissions(temp, meta.permissions());
        }
    }
}

/// The directory an output at `path` goes in (`.` for a bare name), and the first of that
/// directory's ancestors that exists as a file, if any: nothing can be made under it.
pub fn output_parent(path: &Path) -> (&Path, Option<&Path>) {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let file = parent
        .ancestors()
        .find(|a| !a.as_os_str().is_empty() && a.exists() && !a.is_dir());
    (parent, file)
}

/// Fails when `path` is a symbolic link (dangling or not) and not a device or pipe (see
/// [`is_special_file`]; `/dev/stdout` is a link): an output is never written through a
/// link, as a staged directory is never renamed over one, since the link's target may be
/// anywhere (another user's file, a system file).
///
/// # Errors
/// [`Error::Symlink`].
pub fn check_not_symlink(path: &Path) -> Result<()> {
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if link && !is_special_file(path) {
        return Err(Error::Symlink {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// The file `path` names: when `path` is a symbolic link, the file it points to, else
/// `path`. Outputs at links are refused ([`crate::check_writable_target`]); this is for
/// telling which file a path is (the input, another output).
pub fn resolve_output(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => std::fs::canonicalize(path)
            .or_else(|_| {
                // A dangling link: its target, relative to the link's directory.
                std::fs::read_link(path).map(|target| parent_dir(path).join(target))
            })
            .unwrap_or_else(|_| path.to_path_buf()),
        _ => path.to_path_buf(),
    }
}

/// Whether `path`, as given, is a device, FIFO or socket, or names a descriptor the caller
/// opened (`/dev/stdout`, `/dev/fd/3`, `/proc/self/fd/3`; it may be a regular file a shell
/// redirected): written in place, without a temporary file, a rename or a sidecar (a
/// rename would replace the device, and all-or-nothing means nothing for a pipe). Regular
/// files elsewhere under `/dev` (`/dev/shm`) are ordinary outputs.
pub fn is_special_file(path: &Path) -> bool {
    let descriptor = ["/dev/stdout", "/dev/stderr", "/dev/stdin"]
        .iter()
        .any(|name| path == Path::new(name))
        || path.starts_with("/dev/fd")
        || (path.starts_with("/proc") && path.parent().is_some_and(|p| p.ends_with("fd")));
    (descriptor && path.exists())
        || std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// A temporary file `.tinsmith-*.tmp` in `dir`, to be renamed over an output: its mode is
/// what `File::create` would give (the umask decides), not tempfile's private 0600, so the
/// output is readable as any other file the user writes (a web server serving tiles runs
/// as another user). It is locked while open, and the first temporary in `dir` sweeps
/// the stale ones killed runs left there (see [`crate::take_removed_stale`]).
pub(crate) fn output_temp_file(dir: &Path) -> io::Result<tempfile::NamedTempFile> {
    super::stale::sweep_once(dir);
    let temp = temp_builder(0o666).tempfile_in(dir)?;
    super::stale::hold(temp.as_file());
    Ok(temp)
}

/// An unnamed temporary file in `dir` (`O_TMPFILE` on Linux; elsewhere unlinked right after
/// creation), for data spooled on its way to an output there: it vanishes when its
/// handles close, however the process ends. Like a named temporary, the first in `dir`
/// sweeps the stale temporaries there, before the spool fills the disk (a killed run's
/// leftover may be what would fill it).
///
/// # Errors
/// The I/O error of creating the file.
pub fn unnamed_temp_file(dir: &Path) -> io::Result<File> {
    super::stale::sweep_once(dir);
    tempfile::tempfile_in(dir)
}

/// A temporary directory `.tinsmith-*.tmp` in `parent`, to be renamed into place as an
/// output directory: its mode is what `create_dir` would give, not tempfile's 0700.
/// Locked and swept as [`output_temp_file`]'s files are.
pub(crate) fn output_temp_dir(parent: &Path) -> io::Result<OutputTempDir> {
    super::stale::sweep_once(parent);
    let dir = temp_builder(0o777).tempdir_in(parent)?;
    let lock = File::open(dir.path())?;
    super::stale::hold(&lock);
    Ok(OutputTempDir { dir, _lock: lock })
}

/// A temporary output directory (see [`output_temp_dir`]): removed with its contents when
/// dropped, unless [`OutputTempDir::rename_into_place`] moved it.
#[derive(Debug)]
pub(crate) struct OutputTempDir {
    // Dropped first: the directory goes while the lock is still held.
    dir: tempfile::TempDir,
    _lock: File,
}

impl OutputTempDir {
    /// The directory's path.
    pub(crate) fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Renames the directory to `target`, still locked (a sweep cannot take it between).
    /// On failure it is removed with its contents.
    ///
    /// # Errors
    /// The rename's error (`target` is a non-empty directory, on another file system...).
    pub(crate) fn rename_into_place(self, target: &Path) -> io::Result<()> {
        use std::os::unix::fs::MetadataExt;
        let OutputTempDir { dir, _lock: lock } = self;
        let staged = dir.keep();
        // Still the directory made and locked (a program that took it for a killed run's
        // may have removed it, and the writers made a new one in its place).
        let same = match (lock.metadata(), std::fs::symlink_metadata(&staged)) {
            (Ok(made), Ok(now)) => (now.dev(), now.ino()) == (made.dev(), made.ino()),
            _ => false,
        };
        if !same {
            let _ = std::fs::remove_dir_all(&staged);
            return Err(io::Error::other(format!(
                "the temporary directory {} was removed by another program while the run \
                 wrote into it",
                staged.display()
            )));
        }
        std::fs::rename(&staged, target).inspect_err(|_| {
            let _ = std::fs::remove_dir_all(&staged);
        })
    }
}

/// `.tinsmith-*.tmp`, created with `mode` before the umask (Unix).
fn temp_builder(mode: u32) -> tempfile::Builder<'static, 'static> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".tinsmith-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    #[cfg(not(unix))]
    let _ = mode;
    builder
}

/// The directory `path` is in (`.` for a bare name).
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

/// Writes the content of `path` to a synced temporary file beside it; dropping the result
/// without [`Staged::commit`] removes the temporary file. A device or pipe (see
/// [`is_special_file`]) is written in place; a symbolic link is refused.
fn stage<F>(path: &Path, write: F) -> Result<Staged>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> io::Result<()>,
{
    check_not_symlink(path)?;
    let dir = parent_dir(path);
    let io_error = |action: &'static str| {
        move |source: io::Error| Error::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    };
    match std::fs::metadata(dir) {
        Err(error) if error.kind() == io::ErrorKind::NotFound => {
            return Err(Error::MissingDirectory {
                path: path.to_path_buf(),
                dir: dir.to_path_buf(),
            });
        }
        // Anything else (not a directory, no permission) surfaces below with its cause.
        _ => {}
    }

    if is_special_file(path) {
        let mut file = File::options()
            .write(true)
            .open(path)
            .map_err(io_error("open"))?;
        let mut writer = BufWriter::with_capacity(BUFFER_SIZE, &mut file);
        write(&mut writer).map_err(io_error("write"))?;
        writer.flush().map_err(io_error("write"))?;
        return Ok(Staged {
            file: None,
            path: path.to_path_buf(),
        });
    }

    let mut staged = StagedFile::new(path)
        .map_err(io_error("create a temporary file in the output directory"))?;
    if crate::interrupted() {
        // The signal handler may have passed already: the temporary file goes now.
        return Err(io_error("write")(io::Error::from(
            io::ErrorKind::Interrupted,
        )));
    }

    {
        let mut writer = BufWriter::with_capacity(BUFFER_SIZE, staged.file_mut());
        write(&mut writer).map_err(io_error("write"))?;
        writer.flush().map_err(io_error("write"))?;
    }
    staged.file().sync_all().map_err(io_error("write"))?;
    Ok(Staged {
        file: Some(staged),
        path: path.to_path_buf(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn a_staging_directory_replaced_under_the_run_is_not_renamed_into_place() {
        let parent = tempfile::tempdir().expect("temp dir");
        let staged = output_temp_dir(parent.path()).expect("staging dir");
        let path = staged.path().to_path_buf();
        // Another program removes it; a writer makes the path again (a new directory).
        std::fs::remove_dir(&path).expect("rmdir");
        std::fs::create_dir(&path).expect("mkdir");
        std::fs::write(path.join("part"), b"x").expect("write");
        let target = parent.path().join("out");
        let err = staged.rename_into_place(&target).expect_err("refused");
        assert!(
            err.to_string().contains("removed by another program"),
            "{err}"
        );
        assert!(!target.exists() && !path.exists());

        let staged = output_temp_dir(parent.path()).expect("staging dir");
        std::fs::write(staged.path().join("part"), b"x").expect("write");
        staged.rename_into_place(&target).expect("renamed");
        assert!(target.join("part").is_file());
    }

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("read test dir")
            .map(|entry| entry.expect("dir entry").path())
            .collect();
        entries.sort();
        entries
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn descriptors_and_devices_are_special_but_files_under_dev_are_not() {
        assert!(is_special_file(Path::new("/dev/null")));
        assert!(is_special_file(Path::new("/dev/stdout")));
        assert!(is_special_file(Path::new("/proc/self/fd/2")));
        // /dev/shm holds ordinary files: written through a temporary file and a rename.
        let shm = tempfile::NamedTempFile::new_in("/dev/shm").expect("a file in /dev/shm");
        assert!(!is_special_file(shm.path()));
        let dir = tempfile::tempdir().expect("temp dir");
        assert!(!is_special_file(&dir.path().join("new.ply")));
    }

    #[test]
    fn writes_the_file_and_leaves_nothing_else() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.bin");
        write_atomically(&path, |w| w.write_all(b"hello"))?;
        assert_eq!(std::fs::read(&path).expect("read back"), b"hello");
        assert_eq!(entries(dir.path()), vec![path]);
        Ok(())
    }

    #[test]
    fn failure_leaves_no_file_and_no_temporary() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.bin");
        let result = write_atomically(&path, |w| {
            w.write_all(&[7; 100_000])?;
            Err(io::Error::other("generator failed"))
        });
        assert!(
            matches!(
                result,
                Err(Error::Io {
                    action: "write",
                    ..
                })
            ),
            "{result:?}"
        );
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn failure_keeps_the_previous_content() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.bin");
        std::fs::write(&path, b"old").expect("seed");
        let result = write_atomically(&path, |w| {
            w.write_all(b"new but partial")?;
            Err(io::Error::other("generator failed"))
        });
        assert!(result.is_err());
        assert_eq!(std::fs::read(&path).expect("read back"), b"old");
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn success_replaces_the_previous_content() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.bin");
        std::fs::write(&path, b"old content").expect("seed");
        write_atomically(&path, |w| w.write_all(b"new"))?;
        assert_eq!(std::fs::read(&path).expect("read back"), b"new");
        Ok(())
    }

    #[test]
    fn missing_directory_is_named() {
        let dir = tempfile::tempdir().expect("temp dir");
        let missing = dir.path().join("no").join("such");
        let path = missing.join("out.bin");
        let result = write_atomically(&path, |w| w.write_all(b"x"));
        match &result {
            Err(Error::MissingDirectory { path: p, dir: d }) => {
                assert_eq!((p, d), (&path, &missing));
            }
            other => panic!("{other:?}"),
        }
        let message = result.err().map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(
            message,
            format!(
                "{}: output directory {} does not exist",
                path.display(),
                missing.display()
            )
        );
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn target_that_is_a_directory_fails_cleanly() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("taken");
        std::fs::create_dir(&path).expect("mkdir");
        let result = write_atomically(&path, |w| w.write_all(b"x"));
        match &result {
            Err(Error::Io { path: p, .. }) => assert_eq!(p, &path),
            other => panic!("{other:?}"),
        }
        assert!(std::error::Error::source(&result.expect_err("error")).is_some());
        assert!(path.is_dir());
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn parent_that_is_a_file_fails_with_the_cause() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("plain");
        std::fs::write(&file, b"").expect("seed");
        let path = file.join("out.bin");
        let result = write_atomically(&path, |w| w.write_all(b"x"));
        assert!(
            matches!(&result, Err(Error::Io { path: p, .. }) if p == &path),
            "{result:?}"
        );
        assert_eq!(entries(dir.path()), vec![file]);
    }

    #[cfg(unix)]
    #[test]
    fn output_is_not_private_to_the_owner() -> Result<()> {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.bin");
        write_atomically(&path, |w| w.write_all(b"x"))?;
        let mode = std::fs::metadata(&path).expect("stat").permissions().mode();
        // What `File::create` gives under the current umask.
        let reference = dir.path().join("reference");
        File::create(&reference).expect("create");
        let expected = std::fs::metadata(&reference)
            .expect("stat")
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, expected & 0o777);
        Ok(())
    }

    #[cfg(unix)]
    #[test]
    fn an_output_at_a_symbolic_link_is_refused_and_its_target_kept() {
        let dir = tempfile::tempdir().expect("temp dir");
        let real = dir.path().join("real.bin");
        std::fs::write(&real, b"old").expect("seed");
        let link = dir.path().join("link.bin");
        std::os::unix::fs::symlink("real.bin", &link).expect("symlink");
        let dangling = dir.path().join("dangling.bin");
        std::os::unix::fs::symlink("made.bin", &dangling).expect("symlink");
        for path in [&link, &dangling] {
            let err = write_atomically(path, |w| w.write_all(b"new")).expect_err("refused");
            assert!(
                matches!(&err, Error::Symlink { path: p } if p == path),
                "{err:?}"
            );
            assert!(err.to_string().contains("is a symbolic link"), "{err}");
            let input = dir.path().join("in.tif");
            let err =
                crate::check_writable_target(path, &input, Vec::<PathBuf>::new).expect_err("early");
            assert!(matches!(err, Error::Symlink { .. }), "{err:?}");
            let err = crate::ReservedReport::reserve(path).expect_err("report");
            assert!(matches!(err, Error::Symlink { .. }), "{err:?}");
        }
        assert_eq!(std::fs::read(&real).expect("read back"), b"old");
        assert_eq!(entries(dir.path()), vec![dangling, link, real]);
        // A link to a device is written through: nothing is replaced.
        let null = dir.path().join("null");
        std::os::unix::fs::symlink("/dev/null", &null).expect("symlink");
        write_atomically(&null, |w| w.write_all(b"gone")).expect("written to /dev/null");
    }

    #[cfg(unix)]
    #[test]
    fn a_pipe_is_written_in_place_not_replaced() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let fifo = dir.path().join("pipe.ply");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(made.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).expect("read the pipe"))
        };
        write_atomically(&fifo, |w| w.write_all(b"through the pipe"))?;
        assert_eq!(reader.join().expect("reader"), b"through the pipe");
        assert!(is_special_file(&fifo), "the pipe was replaced");
        assert_eq!(entries(dir.path()), vec![fifo]);
        Ok(())
    }

    #[test]
    fn sidecar_is_written_with_the_file_and_not_on_failure() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("out.stl");
        let prj = dir.path().join("out.prj");
        write_atomically_with_sidecar(&path, |w| w.write_all(b"mesh"), Some((&prj, b"WKT")))?;
        assert_eq!(std::fs::read(&prj).expect("prj"), b"WKT");
        assert_eq!(entries(dir.path()), vec![prj.clone(), path.clone()]);

        let other = dir.path().join("other.stl");
        let other_prj = dir.path().join("other.prj");
        let result = write_atomically_with_sidecar(
            &other,
            |w| {
                w.write_all(b"partial")?;
                Err(io::Error::other("generator failed"))
            },
            Some((&other_prj, b"WKT")),
        );
        assert!(result.is_err());
        assert_eq!(entries(dir.path()), vec![prj, path]);
        Ok(())
    }
}
