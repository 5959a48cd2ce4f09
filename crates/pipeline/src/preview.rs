//! `tinsmith preview`: a picture of a raster and a TIN of it, as a PNG.

use tinsmith_preview::{encode_png, render, DrawnSamples, Layers, Scene};
use tinsmith_verify::{MeshRef, VerifyOptions};

use crate::error::{bail, Context};
use crate::mesh_file::{
    mesh_format, read_onto_lattice, read_onto_raster, MeshOnLattice, MeshOnRaster,
};
use crate::{Feedback, MeshJob, PreviewJob, Result};

/// Rasters of up to this many samples (a 5792 x 5792 square) are read whole and the mesh
/// verified at every sample before it is drawn, as `verify` would; larger ones are read
/// only at the samples the picture shows, so that memory follows the picture and the
/// mesh, not the raster. The picture is the same either way.
pub const WHOLE_READ_SAMPLES: u64 = 1 << 25;

/// What [`preview`] drew.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Previewed {
    /// Pixels across and down.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// Raster samples per pixel along each axis.
    pub samples_per_pixel: f64,
    /// The mesh's vertices and triangles.
    pub vertices: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// The largest error at the samples drawn.
    pub max_error: f64,
    /// The largest error at every sample, when the raster was read whole and the mesh
    /// verified ([`WHOLE_READ_SAMPLES`]); `None` when only the drawn samples were read.
    pub verified_max_error: Option<f64>,
    /// The bound the error colours span, when drawn.
    pub error_scale: Option<f64>,
}

/// Reads the mesh back onto its raster's lattice as `verify` does (refusing a vertex that
/// is not on a sample of this raster), draws the layers the job asks for and writes the
/// PNG atomically (an existing file is replaced only by a complete one). The PNG's text
/// chunks name the input, the mesh, the counts and the error at the drawn samples.
///
/// A raster of up to [`WHOLE_READ_SAMPLES`] is read whole and the mesh verified at every
/// sample first: one that is not a valid TIN of it is refused, naming the verifier's
/// first problem. A larger raster is read only at the samples drawn (a lattice about
/// `samples_per_pixel` apart), its mesh checked only on the lattice; the bytes are the
/// same either way.
///
/// # Errors
/// As `verify`, and when the output does not end in `.png`, is the input, cannot be
/// written, or the size is outside 16 to 16,384 pixels.
pub fn preview(job: &PreviewJob) -> Result<Previewed> {
    check_picture_path(&job.output, job.size)?;
    crate::output_paths::check_writable_target(&job.output, &job.input)?;
    let format = check_fits(job)?;
    let mut reader =
        crate::mesh_file::window_reader(&job.input, job.band, job.vertical_datum.as_ref())?;
    let drawn = DrawnSamples::new(reader.width(), reader.height(), job.size)?;
    let (info, values, mesh, verified_max_error) = if reads_whole(&reader) {
        let MeshOnRaster {
            raster,
            positions,
            heights,
            triangles,
            orientation,
            attributes,
        } = read_onto_raster(
            &job.input,
            job.band,
            job.vertical_datum.as_ref(),
            &job.mesh,
            format,
            job.pixel_coords,
        )?;
        let mut joined = None;
        let grid = crate::variables::read_for_check(
            &job.input,
            (&raster.samples, &raster.info),
            &job.variables,
            &mut joined,
        )?;
        let report = tinsmith_verify::verify(
            grid,
            MeshRef::new(&positions, &heights, &triangles),
            &VerifyOptions::new().with_orientation(orientation),
        )
        .with_context(|| format!("{}: cannot verify", job.mesh.display()))?;
        if !report.mesh_is_valid() {
            bail!(
                "{}: not a valid TIN of {} ({}); `tinsmith verify` says more",
                job.mesh.display(),
                job.input.display(),
                report
                    .problems
                    .first()
                    .map_or("the verifier found problems", String::as_str)
            );
        }
        let values = drawn_values(grid.values, grid.width as usize, &drawn);
        let mesh = MeshOnLattice {
            positions,
            heights,
            triangles,
            orientation,
            attributes,
        };
        (raster.info, values, mesh, Some(report.max_error))
    } else {
        let info = reader.info().clone();
        let mesh = read_onto_lattice(&info, &job.mesh, format, job.pixel_coords)?;
        let values = reader.read_lattice(&drawn.columns, &drawn.rows)?;
        (info, values, mesh, None)
    };
    let label = job
        .mesh_label
        .clone()
        .unwrap_or_else(|| job.mesh.display().to_string());
    let drawing = Drawing {
        input: &job.input,
        info: &info,
        drawn: &drawn,
        values: &values,
        positions: &mesh.positions,
        heights: &mesh.heights,
        triangles: &mesh.triangles,
        mesh_label: label,
    };
    let (picture, bytes) = drawing.png(&choices(job))?;
    tinsmith_output::write_bytes_atomically(&job.output, &bytes)
        .with_context(|| format!("{}: cannot write", job.output.display()))?;
    Ok(Previewed {
        width: picture.width,
        height: picture.height,
        samples_per_pixel: picture.samples_per_pixel,
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        max_error: picture.max_error,
        verified_max_error,
        error_scale: picture.error_scale,
    })
}

/// Whether [`preview`] reads the raster whole and verifies the mesh at every sample:
/// rasters of up to [`WHOLE_READ_SAMPLES`] (or the `TINSMITH_TEST_WHOLE_READ_SAMPLES`
/// the tests set, to take the other path on small rasters).
fn reads_whole(reader: &tinsmith_raster::WindowReader) -> bool {
    let limit = std::env::var("TINSMITH_TEST_WHOLE_READ_SAMPLES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(WHOLE_READ_SAMPLES);
    u64::from(reader.width()) * u64::from(reader.height()) <= limit
}

/// The values of the samples `drawn` shows, picked from a whole grid `width` samples
/// across.
pub(crate) fn drawn_values(values: &[f64], width: usize, drawn: &DrawnSamples) -> Vec<f64> {
    let mut out = Vec::with_capacity(drawn.len());
    for &row in &drawn.rows {
        let row = &values[row as usize * width..][..width];
        out.extend(drawn.columns.iter().map(|&c| row[c as usize]));
    }
    out
}

/// Fails when what [`preview`] holds would not fit in memory: the whole raster and the
/// mesh (or, before it exists, a mesh as large as the raster allows) for a raster read
/// whole, else the mesh and the picture's samples; returns the mesh's format.
pub(crate) fn check_fits(job: &PreviewJob) -> Result<tinsmith_formats::MeshFormat> {
    let format = mesh_format(&job.mesh, job.format)?;
    let reader = tinsmith_raster::WindowReader::open(&job.input, job.band)?;
    let size = (reader.width(), reader.height());
    // A mesh not written yet: at most a vertex and two triangles a sample, about 40 bytes.
    let mesh_bytes = match std::fs::metadata(&job.mesh) {
        Ok(_) => crate::memory::mesh_file_memory(&job.mesh, format),
        Err(_) => 0,
    };
    if reads_whole(&reader) {
        // With variables: each band read, and the joined grid's copy of the heights.
        let variables =
            8 * job.variables.len() as u64 + if job.variables.is_empty() { 0 } else { 16 };
        let per_sample = if mesh_bytes == 0 { 80 } else { 40 } + variables;
        crate::memory::check_whole_raster_fits(
            &job.input,
            size,
            crate::memory::Need {
                bytes_per_sample: per_sample,
                extra_bytes: mesh_bytes,
            },
            "preview",
            "a preview reads the whole raster; use a machine with more memory",
        )?;
    } else {
        // Per pixel: a value, the surface, the shade, the colours.
        let pixels = u64::from(job.size) * u64::from(job.size);
        let needed = pixels * 28 + mesh_bytes;
        crate::memory::check_fits(needed, |needed, available| {
            format!(
                "{}: drawing it needs about {needed:.1} GB (the mesh and the picture), and \
                 {available:.1} GB is available; use a machine with more memory",
                job.mesh.display()
            )
        })?;
    }
    Ok(format)
}

/// What a picture shows and how large it is.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PictureChoices {
    pub(crate) size: u32,
    pub(crate) hillshade: bool,
    pub(crate) wireframe: bool,
    pub(crate) error: bool,
    /// The error colours' span (default: the measured largest error).
    pub(crate) max_error: Option<f64>,
}

fn choices(job: &PreviewJob) -> PictureChoices {
    PictureChoices {
        size: job.size,
        hillshade: job.hillshade,
        wireframe: job.wireframe,
        error: job.error,
        max_error: job.max_error,
    }
}

/// A raster seen at the samples a picture shows, and a TIN on its lattice, to draw.
pub(crate) struct Drawing<'a> {
    pub(crate) input: &'a std::path::Path,
    pub(crate) info: &'a tinsmith_raster::RasterInfo,
    /// The samples the picture shows.
    pub(crate) drawn: &'a DrawnSamples,
    /// Their values, row-major, NaN for nodata ([`drawn_values`]).
    pub(crate) values: &'a [f64],
    pub(crate) positions: &'a [[i64; 2]],
    pub(crate) heights: &'a [f64],
    pub(crate) triangles: &'a [[u32; 3]],
    /// What the PNG's text calls the mesh.
    pub(crate) mesh_label: String,
}

/// A drawn picture's size and scale, and the error measured at its samples.
pub(crate) struct Drawn {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) samples_per_pixel: f64,
    /// The largest |TIN - raster| at the drawn samples both have.
    pub(crate) max_error: f64,
    pub(crate) error_scale: Option<f64>,
}

impl Drawing<'_> {
    /// The picture `choices` ask for, as PNG bytes with text chunks naming the input, the
    /// mesh, the counts and the largest error at the drawn samples.
    pub(crate) fn png(&self, choices: &PictureChoices) -> Result<(Drawn, Vec<u8>)> {
        let (width, height) = (self.info.width, self.info.height);
        let tin = MeshRef::new(self.positions, self.heights, self.triangles);
        let drawn = self.drawn;
        let surface = tinsmith_verify::surface_at(width, height, tin, &drawn.columns, &drawn.rows)?;
        let max_error = surface
            .iter()
            .zip(self.values)
            .map(|(t, v)| (t - v).abs())
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max);
        let error_scale = choices.error.then(|| {
            choices
                .max_error
                .filter(|&e| e > 0.0)
                .unwrap_or(if max_error > 0.0 { max_error } else { 1.0 })
        });
        let scene = Scene {
            drawn,
            values: self.values,
            resolution: resolution(self.info).unwrap_or_else(|| {
                unit_free_resolution(self.values, drawn.columns.len(), drawn.samples_per_pixel)
            }),
            positions: self.positions,
            triangles: self.triangles,
            surface: Some(&surface),
        };
        let layers = Layers {
            hillshade: choices.hillshade,
            wireframe: choices.wireframe,
            error: error_scale,
            title: match choices.max_error {
                Some(_) => "error, TIN - raster (to the bound)".into(),
                None => "error, TIN - raster (to the largest)".into(),
            },
        };
        let picture = render(&scene, &layers)?;
        let text = [
            (
                "Software",
                format!("tinsmith {}", env!("CARGO_PKG_VERSION")),
            ),
            ("Source", self.input.display().to_string()),
            ("Mesh", self.mesh_label.clone()),
            (
                "Counts",
                format!(
                    "{} vertices, {} triangles",
                    self.positions.len(),
                    self.triangles.len()
                ),
            ),
            (
                "Max error at drawn samples",
                tinsmith_georef::readable(max_error),
            ),
            (
                "Error scale",
                error_scale.map_or("none".into(), tinsmith_georef::readable),
            ),
            (
                "Samples per pixel",
                tinsmith_georef::readable(picture.samples_per_pixel),
            ),
        ];
        let bytes = encode_png(&picture, &text);
        let drawn = Drawn {
            width: picture.width,
            height: picture.height,
            samples_per_pixel: picture.samples_per_pixel,
            max_error,
            error_scale,
        };
        Ok((drawn, bytes))
    }
}

/// Fails unless `path` ends in `.png` and `size` is drawable, before any work.
pub(crate) fn check_picture_path(path: &std::path::Path, size: u32) -> Result<()> {
    let is_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        bail!(
            "{}: a preview is a PNG; give an output ending in .png",
            path.display()
        );
    }
    if !(16..=16_384).contains(&size) {
        bail!("--size {size}: a preview is 16 to 16384 pixels on its longer side");
    }
    Ok(())
}

/// Sample spacing for the hillshade, in metres where the raster's CRS is geographic
/// (degrees at the raster's middle latitude), else in its own units; `None` for a raster
/// without a transform.
fn resolution(info: &tinsmith_raster::RasterInfo) -> Option<[f64; 2]> {
    let gt = info.geo_transform?;
    let geographic = info
        .crs_wkt
        .as_deref()
        .is_some_and(|wkt| tinsmith_raster::is_geographic(wkt).unwrap_or(false));
    if !geographic {
        return Some([gt[1], gt[5]]);
    }
    let middle = gt[3] + gt[5] * f64::from(info.height) / 2.0;
    let metres = 111_320.0;
    Some([
        gt[1] * metres * middle.to_radians().cos().max(0.01),
        gt[5] * metres,
    ])
}

/// A sample spacing for a raster whose spacing is unknown (no transform): the one that
/// makes the steepest tenth of the steps between neighbouring drawn samples (`width`
/// across, about `samples_per_pixel` samples apart, or 1 when fewer) 45°, so that its
/// relief reads whatever the heights' unit.
fn unit_free_resolution(values: &[f64], width: usize, samples_per_pixel: f64) -> [f64; 2] {
    let spacing = unit_free_lattice_spacing(values, width) / samples_per_pixel.max(1.0);
    [spacing, -spacing]
}

/// The drawn lattice's spacing [`unit_free_resolution`] picks.
fn unit_free_lattice_spacing(values: &[f64], width: usize) -> f64 {
    let mut steps: Vec<f64> = values
        .windows(2)
        .enumerate()
        .filter(|(k, _)| (k + 1) % width != 0)
        .map(|(_, pair)| (pair[1] - pair[0]).abs())
        .filter(|d| d.is_finite())
        .collect();
    if steps.is_empty() {
        return 1.0;
    }
    let k = steps.len() * 9 / 10;
    let (_, step, _) = steps.select_nth_unstable_by(k, f64::total_cmp);
    if *step > 0.0 {
        *step
    } else {
        1.0
    }
}

/// [`preview`] of the TIN `decimate` makes (its `output` is ignored): the mesh is written to
/// a temporary PLY (removed after), verified as `mesh` verifies it, and drawn from there.
/// The PNG's "Mesh" text says it was decimated, within which bound.
///
/// # Errors
/// As `mesh` and [`preview`].
pub fn preview_decimated(
    job: &PreviewJob,
    decimate: &MeshJob,
    feedback: &dyn Feedback,
) -> Result<Previewed> {
    let scratch = tempfile::Builder::new()
        .prefix(".tinsmith-preview-")
        .tempdir()
        .with_context(|| "cannot make a temporary directory for the mesh")?;
    let mesh = scratch.path().join("decimated.ply");
    let mut decimate = decimate.clone();
    decimate.input = job.input.clone();
    decimate.output = Some(mesh.clone());
    decimate.export.format = None;
    decimate.band = job.band;
    decimate.pixel_coords = job.pixel_coords;
    decimate.vertical_datum = job.vertical_datum.clone();
    decimate.report = None;
    crate::mesh(&decimate, feedback)?;
    let mut from_mesh = job.clone();
    from_mesh.mesh = mesh;
    from_mesh.format = None;
    from_mesh.max_error = job.max_error.or(decimate.decimation.max_error);
    let bound = decimate
        .decimation
        .max_error
        .map_or("a count target".to_owned(), tinsmith_georef::readable);
    from_mesh.mesh_label = Some(format!("decimated by tinsmith within {bound}"));
    preview(&from_mesh)
}
