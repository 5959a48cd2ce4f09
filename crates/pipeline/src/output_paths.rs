//! The pipeline's side of output handling: the `.prj` sidecar rules (which know mesh formats
//! and CRSs) and the notes printed about outputs; the checks of output paths and the
//! reserved reports themselves are `tinsmith_output`'s, given here the input's file list.

use std::path::{Path, PathBuf};

use tinsmith_formats::MeshFormat;

use crate::error::bail;
use crate::Feedback;
use crate::Result;

pub use tinsmith_output::{check_distinct, check_not_inside, ReservedReport};

/// Fails early, before long work, when `path` cannot or must not take an output (see
/// [`tinsmith_output::check_writable_target`]), among others when it is the `input` file
/// or one the input is read from (the input itself or any file GDAL reads with it).
pub fn check_writable_target(path: &Path, input: &Path) -> Result<()> {
    Ok(tinsmith_output::check_writable_target(path, input, || {
        input_files(input)
    })?)
}

/// Fails when the `.prj` sidecar a georeferenced mesh in `format` writes beside `output`
/// should not be replaced: it is one of the files GDAL reads the input from (an ESRI ASCII
/// grid keeps its CRS in its `.prj`); it is read-only; or it holds another
/// CRS than `crs_wkt` (the raster's) while no file is at `output`, so it is not from an
/// earlier mesh there but another file's (a shapefile's of the same name). Output to a
/// device or pipe writes no sidecar; a sidecar at a symbolic link is refused, as any output
/// is. (With `--pixel-coords` no sidecar is written.)
pub fn check_sidecar(
    output: &Path,
    input: &Path,
    format: MeshFormat,
    crs_wkt: Option<&str>,
) -> Result<()> {
    if !format.uses_prj_sidecar() || tinsmith_output::is_special_file(output) {
        return Ok(());
    }
    let ours = tinsmith_formats::prj_path(output);
    if crs_wkt.is_some() {
        tinsmith_output::check_not_symlink(&ours)?;
    }
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
    let prj = tinsmith_formats::prj_path(output);
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
            &tinsmith_formats::prj_path(output),
            report,
            "the output's CRS sidecar",
        )?;
    }
    Ok(())
}

/// Prefixes errors with the input file's path, unless their message names it already
/// (the raster reader's errors do), so that a message names the file exactly once.
pub trait NamingFile<T> {
    /// The result, its error naming `path`.
    fn naming_file(self, path: &Path) -> Result<T>;
}

impl<T, E: Into<crate::Error>> NamingFile<T> for std::result::Result<T, E> {
    fn naming_file(self, path: &Path) -> Result<T> {
        self.map_err(|e| {
            let e: crate::Error = e.into();
            let shown = path.display().to_string();
            if e.chain_text().contains(&shown) {
                e
            } else {
                e.context(shown)
            }
        })
    }
}
