//! Checks of output paths made before long work, so that a run that cannot write its
//! outputs fails at once rather than after the work.

use std::path::{Path, PathBuf};

use super::atomic::{check_not_symlink, output_parent, parent_dir, resolve_output};
use crate::error::{Error, Result};

/// Fails early, before long work, when `path` ends with '/', is a looping symbolic link,
/// has a name too long for its file system, is the `input` file or one the input is read
/// from (see `check_not_input`), is a symbolic link (outputs are not written through
/// links), is a directory, is a read-only file or one the directory's sticky bit keeps
/// this user from replacing, or its directory is missing.
///
/// # Errors
/// The first of those found, as the [`Error`] variant of that name.
pub fn check_writable_target<F, L>(path: &Path, input: &Path, input_files: F) -> Result<()>
where
    F: Fn() -> L,
    L: AsRef<[PathBuf]>,
{
    let path_buf = || path.to_path_buf();
    if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        return Err(Error::EndsWithSlash { path: path_buf() });
    }
    if std::fs::metadata(path).is_err_and(|e| e.raw_os_error() == Some(libc::ELOOP)) {
        return Err(Error::SymlinkLoop { path: path_buf() });
    }
    if std::fs::symlink_metadata(path).is_err_and(|e| e.raw_os_error() == Some(libc::ENAMETOOLONG))
    {
        return Err(Error::NameTooLong { path: path_buf() });
    }
    check_not_input(path, input, input_files)?;
    check_not_symlink(path)?;
    let (dir, file_in_the_way) = output_parent(path);
    if let Some(file) = file_in_the_way {
        return Err(Error::FileInTheWay {
            path: path_buf(),
            file: file.to_path_buf(),
        });
    }
    if !dir.is_dir() {
        return Err(Error::MissingDirectory {
            path: path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    if path.is_dir() {
        return Err(Error::IsDirectory { path: path_buf() });
    }
    // The write renames a new file over it, which the directory allows whatever the file's
    // mode: a file made read-only is not replaced behind its owner's back.
    if std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().readonly()) {
        return Err(Error::ReadOnly { path: path_buf() });
    }
    if sticky_keeps(path) {
        return Err(Error::StickyOwner { path: path_buf() });
    }
    Ok(())
}

/// Whether `target` exists in a sticky directory (mode +t) that keeps this process from
/// renaming a new file over it: neither the file nor the directory is this user's, and
/// the user is not root.
#[cfg(unix)]
#[allow(unsafe_code)]
fn sticky_keeps(target: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    // SAFETY: geteuid has no preconditions and cannot fail.
    let user = unsafe { libc::geteuid() };
    let (Ok(file), Ok(dir)) = (
        std::fs::symlink_metadata(target),
        std::fs::metadata(parent_dir(target)),
    ) else {
        return false;
    };
    user != 0 && dir.mode() & 0o1000 != 0 && file.uid() != user && dir.uid() != user
}

#[cfg(not(unix))]
fn sticky_keeps(_target: &Path) -> bool {
    false
}

/// Fails when `output` is the file `input` or one of `input_files` (what the input is
/// read from with it: a VRT's source, an ENVI header, a `.prj` or `.aux.xml` sidecar), by
/// any path, links included: writing would destroy or change the input. `input_files` is
/// called only when `output` exists.
///
/// # Errors
/// [`Error::IsInput`] or [`Error::ReadByInput`].
pub fn check_not_input<F, L>(output: &Path, input: &Path, input_files: F) -> Result<()>
where
    F: Fn() -> L,
    L: AsRef<[PathBuf]>,
{
    let Ok(target) = std::fs::canonicalize(resolve_output(output)) else {
        return Ok(());
    };
    let own = std::fs::canonicalize(input).ok();
    if own.as_ref() == Some(&target) {
        return Err(Error::IsInput {
            path: output.to_path_buf(),
            input: input.to_path_buf(),
        });
    }
    if input_files().as_ref().contains(&target) {
        return Err(Error::ReadByInput {
            path: output.to_path_buf(),
            input: input.to_path_buf(),
        });
    }
    Ok(())
}

/// Fails when two files of one run are the same file (by any path, links included, whether
/// they exist yet or not): `second` (described as `what`) would overwrite or destroy
/// `first`, e.g. `--report` naming the output mesh, or an output naming the `--mesh` input.
///
/// # Errors
/// [`Error::SameFile`].
pub fn check_distinct(first: &Path, second: &Path, what: &str) -> Result<()> {
    if let (Some(a), Some(b)) = (file_identity(first), file_identity(second)) {
        if a == b {
            return Err(Error::SameFile {
                path: second.to_path_buf(),
                other: first.to_path_buf(),
                what: what.to_owned(),
            });
        }
    }
    Ok(())
}

/// A path that names the same file as every other path to it: the canonical path when the
/// file exists, else the canonical directory joined with the file name.
fn file_identity(path: &Path) -> Option<PathBuf> {
    let target = resolve_output(path);
    std::fs::canonicalize(&target).ok().or_else(|| {
        let name = target.file_name()?;
        Some(std::fs::canonicalize(parent_dir(&target)).ok()?.join(name))
    })
}

/// Fails when `report` would be written inside `dir`, a directory the run fills with its
/// own files (a `tiles` pyramid, `--per-tile` meshes), described as `what`: the report
/// could replace one of them (`layer.json`) or be taken for one.
///
/// # Errors
/// [`Error::InsideOutputDir`].
pub fn check_not_inside(dir: &Path, report: &Path, what: &str) -> Result<()> {
    let absolute = |p: &Path| std::fs::canonicalize(p).or_else(|_| std::path::absolute(p));
    // The report's directory as it resolves, and its own name: the report may not exist.
    let report_path = match (absolute(parent_dir(report)), report.file_name()) {
        (Ok(parent), Some(name)) => Ok(parent.join(name)),
        (parent, _) => parent,
    };
    if let (Ok(resolved), Ok(report_path)) = (absolute(dir), report_path) {
        // Inside it, or the directory itself (the report's rename would fail at the end).
        if report_path.starts_with(&resolved) {
            return Err(Error::InsideOutputDir {
                path: report.to_path_buf(),
                dir: dir.to_path_buf(),
                what: what.to_owned(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_files() -> Vec<PathBuf> {
        Vec::new()
    }

    #[test]
    fn messages_name_the_target() {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("in.tif");
        std::fs::write(&input, b"").expect("write");
        let err = check_writable_target(Path::new("out/"), &input, no_files).expect_err("slash");
        assert_eq!(
            err.to_string(),
            "out/: ends with '/', which names a directory, not an output file"
        );
        let err = check_writable_target(&input, &input, no_files).expect_err("input");
        assert_eq!(
            err.to_string(),
            format!(
                "{0}: is the input file {0}; writing there would destroy it",
                input.display()
            )
        );
        let err = check_writable_target(dir.path(), &input, no_files).expect_err("dir");
        assert!(matches!(err, Error::IsDirectory { .. }), "{err:?}");
        let report = dir.path().join("r.json");
        let err = check_distinct(&report, &report, "the output").expect_err("same");
        assert_eq!(
            err.to_string(),
            format!(
                "{0}: is also the output {0}; one would overwrite the other",
                report.display()
            )
        );
        assert!(check_writable_target(&report, &input, no_files).is_ok());
    }
}
