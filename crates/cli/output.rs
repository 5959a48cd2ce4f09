//! Checks and atomic writes for output files the CLI writes itself (reports).

use std::io::Write;
use std::path::Path;

use anyhow::{bail, Context, Result};
use tinsmith_export::MeshFormat;

/// Fails early, before long work, when `path`'s directory is missing, `path` is a
/// directory, or `path` is the `input` file.
pub fn check_writable_target(path: &Path, input: &Path) -> Result<()> {
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
    Ok(())
}

/// Fails when the `.prj` sidecar a georeferenced mesh in `format` writes beside `output`
/// is the input's own `.prj` (an ESRI ASCII grid keeps its CRS there) or another file the
/// input is read from: writing it would change the input. (With `--pixel-coords` no
/// sidecar is written.)
pub fn check_sidecar_not_input(output: &Path, input: &Path, format: MeshFormat) -> Result<()> {
    if !format.uses_prj_sidecar() {
        return Ok(());
    }
    let ours = tinsmith_export::prj_path(output);
    if let Ok(a) = std::fs::canonicalize(&ours) {
        let theirs = std::fs::canonicalize(tinsmith_export::prj_path(input)).ok();
        if theirs.as_ref() == Some(&a) || tinsmith_raster::input_files(input).contains(&a) {
            bail!(
                "{}: its CRS would go to {}, which belongs to the input {}; choose another \
                 output name",
                output.display(),
                ours.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Notes on stderr (unless `quiet`) that the `.prj` beside `output` was left as it is,
/// when a mesh in a sidecar format (OBJ, STL, glTF) was written there without a CRS:
/// readers would take that file for the mesh's CRS. It is never removed, since it may
/// belong to another file (the input's grid, a shapefile of the same name).
pub fn note_prj_left_beside(output: &Path, format: MeshFormat, crs_written: bool, quiet: bool) {
    let prj = tinsmith_export::prj_path(output);
    if quiet || crs_written || !format.uses_prj_sidecar() || !prj.is_file() {
        return;
    }
    note!(
        "{}: written without a CRS, but {} is beside it and was left as it is; readers \
         may take it for this mesh's CRS (remove it if it came from an earlier run)",
        output.display(),
        prj.display()
    );
}

/// Notes on stderr (unless `quiet` or `pixel_coords`) that a raster placed only by ground
/// control points is written in pixel coordinates: tinsmith does not georeference by GCPs.
pub fn note_gcps_unused(info: &tinsmith_raster::RasterInfo, pixel_coords: bool, quiet: bool) {
    if quiet || pixel_coords || info.geo_transform.is_some() || info.gcp_count == 0 {
        return;
    }
    note!(
        "{}: georeferenced only by {} ground control points (GCPs), which tinsmith does not \
         use: the output is in pixel (column, row) coordinates; for world coordinates warp \
         it onto a grid first, e.g. `gdalwarp {} warped.tif`",
        info.path.display(),
        info.gcp_count,
        info.path.display()
    );
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
    if tinsmith_raster::input_files(input).contains(&target) {
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

/// Writes `bytes` to `path` through a temporary file in the same directory and an atomic
/// rename: `path` is either untouched or complete. A symlink is followed (it stays a
/// link); a device or pipe is written in place.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = tinsmith_export::resolve_output(path);
    if tinsmith_export::is_special_file(&target) {
        return std::fs::write(&target, bytes)
            .with_context(|| format!("{}: write failed", path.display()));
    }
    let dir = parent_dir(&target);
    let mut tmp = tinsmith_export::output_temp_file(dir).with_context(|| {
        format!(
            "{}: cannot create a file in {}",
            path.display(),
            dir.display()
        )
    })?;
    tmp.write_all(bytes)
        .with_context(|| format!("{}: write failed", path.display()))?;
    tmp.persist(&target)
        .with_context(|| format!("{}: cannot write", path.display()))?;
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
