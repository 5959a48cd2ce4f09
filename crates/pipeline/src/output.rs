//! Checks and atomic writes for output files the CLI writes itself (reports).

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use tinsmith_export::MeshFormat;

use crate::Feedback;

/// Fails early, before long work, when `path` ends with '/', is a looping symbolic link,
/// has a name too long for its file system, is the `input` file or one the input is read
/// from (see [`check_not_input`]), is a directory, is a read-only file or one the
/// directory's sticky bit keeps this user from replacing, or its directory is missing.
pub fn check_writable_target(path: &Path, input: &Path) -> Result<()> {
    if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        bail!(
            "{}: ends with '/', which names a directory, not an output file",
            path.display()
        );
    }
    if std::fs::metadata(path).is_err_and(|e| e.raw_os_error() == Some(libc::ELOOP)) {
        bail!(
            "{}: is a symbolic link that loops (or a chain of too many); point it at a file \
             or remove it",
            path.display()
        );
    }
    if std::fs::symlink_metadata(path).is_err_and(|e| e.raw_os_error() == Some(libc::ENAMETOOLONG))
    {
        bail!(
            "{}: the name is too long for its file system; choose a shorter one",
            path.display()
        );
    }
    check_not_input(path, input)?;
    let (dir, file_in_the_way) = tinsmith_export::output_parent(path);
    if let Some(file) = file_in_the_way {
        bail!(
            "{}: {} is a file, not a directory",
            path.display(),
            file.display()
        );
    }
    if !dir.is_dir() {
        bail!(
            "{}: output directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    if path.is_dir() {
        bail!("{}: is a directory, not an output file", path.display());
    }
    // The write renames a new file over it, which the directory allows whatever the file's
    // mode: a file made read-only is not replaced behind its owner's back.
    let target = tinsmith_export::resolve_output(path);
    if std::fs::metadata(&target).is_ok_and(|m| m.is_file() && m.permissions().readonly()) {
        bail!(
            "{}: exists and is read-only; make it writable (chmod u+w) or remove it to \
             replace it",
            path.display()
        );
    }
    if sticky_keeps(&target) {
        bail!(
            "{}: belongs to another user in a directory where only a file's owner may \
             replace it (sticky bit, as in /tmp); choose another name",
            path.display()
        );
    }
    Ok(())
}

/// Whether `target` exists in a sticky directory (mode +t) that keeps this process from
/// renaming a new file over it: neither the file nor the directory is this user's, and
/// the user is not root.
#[cfg(unix)]
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

/// Fails when the `.prj` sidecar a georeferenced mesh in `format` writes beside `output`
/// should not be replaced: it is one of the files GDAL reads the input from (an ESRI ASCII
/// grid keeps its CRS in its `.prj`); it is read-only; or it holds another
/// CRS than `crs_wkt` (the raster's) while no file is at `output`, so it is not from an
/// earlier mesh there but another file's (a shapefile's of the same name). Output to a
/// device or pipe writes no sidecar. (With `--pixel-coords` no sidecar is written.)
pub fn check_sidecar(
    output: &Path,
    input: &Path,
    format: MeshFormat,
    crs_wkt: Option<&str>,
) -> Result<()> {
    if !format.uses_prj_sidecar() || tinsmith_export::is_special_file(output) {
        return Ok(());
    }
    let ours = tinsmith_export::prj_path(output);
    // GDAL's file list of the input names its `.prj` when it reads one (ESRI ASCII, EHdr);
    // a `.prj` merely named like a GeoTIFF input is not the input's (it is usually the
    // sidecar of an earlier mesh of it).
    if let Ok(a) = std::fs::canonicalize(&ours) {
        if input_files(input).contains(&a) {
            bail!(
                "{}: its CRS would go to {}, which belongs to the input {}; choose another \
                 output name",
                output.display(),
                ours.display(),
                input.display()
            );
        }
    }
    let (Some(wkt), Ok(meta)) = (crs_wkt, std::fs::metadata(&ours)) else {
        // No CRS, no sidecar (see `note_prj_left_beside`); or none there yet.
        return Ok(());
    };
    if meta.is_dir() {
        bail!(
            "{}: its CRS would go to {}, which is a directory; choose another output name",
            output.display(),
            ours.display()
        );
    }
    if meta.is_file() && meta.permissions().readonly() {
        bail!(
            "{}: its CRS would replace {}, which is read-only; make it writable (chmod u+w) \
             or remove it, or choose another output name",
            output.display(),
            ours.display()
        );
    }
    // The same CRS in another spelling (ESRI's, GDAL's `.prj` of the input) counts.
    let same_crs = std::fs::read_to_string(&ours)
        .is_ok_and(|held| held.trim() == wkt.trim() || tinsmith_raster::same_crs(held.trim(), wkt));
    if !same_crs && !output.exists() {
        bail!(
            "{}: its CRS would replace {}, which holds another CRS and is not from an \
             earlier mesh here (there is no {}): it may be another file's (a shapefile's); \
             remove it or choose another output name",
            output.display(),
            ours.display(),
            output.display()
        );
    }
    Ok(())
}

/// Notes that the `.prj` beside `output` was left as it is,
/// when a mesh in a sidecar format (OBJ, STL, glTF) was written there without a CRS:
/// readers would take that file for the mesh's CRS. It is never removed, since it may
/// belong to another file (the input's grid, a shapefile of the same name).
pub fn note_prj_left_beside(
    output: &Path,
    format: MeshFormat,
    crs_written: bool,
    feedback: &dyn Feedback,
) {
    let prj = tinsmith_export::prj_path(output);
    if crs_written || !format.uses_prj_sidecar() || !prj.is_file() {
        return;
    }
    feedback.note(&format!(
        "{}: written without a CRS, but {} is beside it and was left as it is; readers \
         may take it for this mesh's CRS (remove it if it came from an earlier run)",
        output.display(),
        prj.display()
    ));
}

/// [`tinsmith_raster::input_files`] of `input`, opened once per run: every output path of
/// a run (the mesh, its sidecar, the report) is checked against the same input.
fn input_files(input: &Path) -> std::borrow::Cow<'static, [PathBuf]> {
    static FILES: std::sync::OnceLock<(PathBuf, Vec<PathBuf>)> = std::sync::OnceLock::new();
    let (path, files) =
        FILES.get_or_init(|| (input.to_path_buf(), tinsmith_raster::input_files(input)));
    if path == input {
        files.as_slice().into()
    } else {
        tinsmith_raster::input_files(input).into()
    }
}

/// Notes (unless `pixel_coords`) that a raster placed only by ground
/// control points or geolocation arrays is written in pixel coordinates: tinsmith
/// georeferences by a geotransform only.
pub fn note_gcps_unused(
    info: &tinsmith_raster::RasterInfo,
    pixel_coords: bool,
    feedback: &dyn Feedback,
) {
    if pixel_coords || info.geo_transform.is_some() {
        return;
    }
    let (by, warp) = match (info.gcp_count, info.geolocation) {
        (0, false) => return,
        (0, true) => ("geolocation arrays".to_owned(), "gdalwarp -geoloc"),
        (n, _) => (format!("{n} ground control points (GCPs)"), "gdalwarp"),
    };
    feedback.note(&format!(
        "{}: georeferenced only by {by}, which tinsmith does not use: the output is in pixel \
         (column, row) coordinates; for world coordinates warp it onto a grid first, e.g. \
         `{warp} {} warped.tif`",
        info.path.display(),
        info.path.display()
    ));
}

/// Fails when `output` is the file `input` or one GDAL reads with it (a VRT's source, an
/// ENVI header, a `.prj` or `.aux.xml` sidecar: see [`tinsmith_raster::input_files`]), by
/// any path, links included: writing would destroy or change the input.
pub fn check_not_input(output: &Path, input: &Path) -> Result<()> {
    let Ok(target) = std::fs::canonicalize(tinsmith_export::resolve_output(output)) else {
        return Ok(());
    };
    let own = std::fs::canonicalize(input).ok();
    if own.as_ref() == Some(&target) {
        bail!(
            "{}: is the input raster {}; writing there would destroy it",
            output.display(),
            input.display()
        );
    }
    if input_files(input).contains(&target) {
        bail!(
            "{}: is a file the input raster {} is read from (GDAL lists it among the \
             input's files); writing there would change or destroy the input",
            output.display(),
            input.display()
        );
    }
    Ok(())
}

/// Fails when two files of one run are the same file (by any path, links included, whether
/// they exist yet or not): `second` (described as `what`) would overwrite or destroy
/// `first`, e.g. `--report` naming the output mesh, or an output naming the `--mesh` input.
pub fn check_distinct(first: &Path, second: &Path, what: &str) -> Result<()> {
    if let (Some(a), Some(b)) = (file_identity(first), file_identity(second)) {
        if a == b {
            bail!(
                "{}: is also {} {}; one would overwrite the other",
                second.display(),
                what,
                first.display()
            );
        }
    }
    Ok(())
}

/// A path that names the same file as every other path to it: the canonical path when the
/// file exists, else the canonical directory joined with the file name.
fn file_identity(path: &Path) -> Option<std::path::PathBuf> {
    let target = tinsmith_export::resolve_output(path);
    std::fs::canonicalize(&target).ok().or_else(|| {
        let name = target.file_name()?;
        Some(std::fs::canonicalize(parent_dir(&target)).ok()?.join(name))
    })
}

/// Room for a `--report` file taken before the run's outputs are committed: its temporary
/// file is made and [`REPORT_RESERVE_BYTES`] written when the run starts, so a report that
/// cannot be written (a full disk, a directory that refuses files) fails the run before any
/// output is in place, rather than after (an error exit with the outputs left behind).
/// [`ReservedReport::write`] then overwrites the bytes already taken.
pub struct ReservedReport {
    path: PathBuf,
    target: PathBuf,
    file: Option<(tempfile::NamedTempFile, tinsmith_export::PendingGuard)>,
}

/// More than any report needs: a `mesh` report is about 1 KB, a `tiles` report about
/// 0.6 KB plus 0.3 KB per level (10 KB at 32 levels).
pub const REPORT_RESERVE_BYTES: usize = 16 * 1024;

impl ReservedReport {
    /// Creates the report's temporary file beside `path` and fills it with
    /// [`REPORT_RESERVE_BYTES`] spaces (a device or pipe is written in place, later).
    pub fn reserve(path: &Path) -> Result<ReservedReport> {
        let target = tinsmith_export::resolve_output(path);
        if tinsmith_export::is_special_file(path) {
            return Ok(ReservedReport {
                path: path.to_path_buf(),
                target,
                file: None,
            });
        }
        let dir = parent_dir(&target);
        let mut tmp = tinsmith_export::output_temp_file(dir).with_context(|| {
            format!(
                "{}: cannot create a file in {}",
                path.display(),
                dir.display()
            )
        })?;
        let guard = tinsmith_export::track_pending(tmp.path());
        tmp.write_all(&[b' '; REPORT_RESERVE_BYTES])
            .and_then(|()| tmp.flush())
            .with_context(|| format!("{}: write failed", path.display()))?;
        Ok(ReservedReport {
            path: path.to_path_buf(),
            target,
            file: Some((tmp, guard)),
        })
    }

    /// Writes `bytes` as the report, over the reserved room, and renames it into place.
    pub fn write(self, bytes: &[u8]) -> Result<()> {
        let failed = || format!("{}: write failed", self.path.display());
        let Some((mut tmp, _guard)) = self.file else {
            return std::fs::write(&self.path, bytes).with_context(failed);
        };
        tmp.seek(SeekFrom::Start(0))
            .and_then(|_| tmp.write_all(bytes))
            .and_then(|()| tmp.flush())
            .and_then(|()| tmp.as_file().set_len(bytes.len() as u64))
            .with_context(failed)?;
        tinsmith_export::keep_permissions(tmp.path(), &self.target);
        tmp.persist(&self.target)
            .with_context(|| format!("{}: cannot write", self.path.display()))?;
        Ok(())
    }
}

/// Fails when `report` is the `.prj` sidecar a georeferenced mesh in `format` writes beside
/// `output`: one would overwrite the other.
pub fn check_distinct_from_sidecar(
    output: &Path,
    report: &Path,
    format: MeshFormat,
    pixel_coords: bool,
) -> Result<()> {
    if format.uses_prj_sidecar() && !pixel_coords {
        check_distinct(
            &tinsmith_export::prj_path(output),
            report,
            "the output's CRS sidecar",
        )?;
    }
    Ok(())
}

/// Fails when `report` would be written inside `dir`, a directory the run fills with its
/// own files (a `tiles` pyramid, `--per-tile` meshes): the report could replace one of them
/// (`layer.json`) or be taken for one.
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
            bail!(
                "{}: is {what} {} or inside it; write the report elsewhere",
                report.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Prefixes errors with the input file's path, unless their message names it already
/// (the raster reader's errors do), so that a message names the file exactly once.
pub trait NamingFile<T> {
    /// The result, its error naming `path`.
    fn naming_file(self, path: &Path) -> Result<T>;
}

impl<T, E: Into<anyhow::Error>> NamingFile<T> for std::result::Result<T, E> {
    fn naming_file(self, path: &Path) -> Result<T> {
        self.map_err(|e| {
            let e: anyhow::Error = e.into();
            let shown = path.display().to_string();
            if format!("{e:#}").contains(&shown) {
                e
            } else {
                e.context(shown)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reserved_report_holds_exactly_what_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.json");
        let reserved = ReservedReport::reserve(&path).unwrap();
        // The room is taken (in a temporary file) before anything is written.
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        reserved.write(b"{}\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"{}\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_report_that_cannot_be_reserved_fails_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("r.json");
        let err = ReservedReport::reserve(&path).err().unwrap();
        assert!(format!("{err:#}").contains("r.json"), "{err:#}");
    }
}
