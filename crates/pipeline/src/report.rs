//! The `--report` JSON of `tinsmith mesh`, shared by the untiled and the tiled paths.

use std::path::Path;

use serde::Serialize;
use tinsmith_core::VertexHeights;
use tinsmith_georef::readable;

use crate::jobs::MeshJob;
use crate::Feedback;

/// What every mesh report says: the input, the options, the counts before and after, the
/// bound and the independently measured error, and where the mesh went.
#[derive(Debug, Serialize)]
pub struct MeshSummary<'a> {
    #[serde(serialize_with = "lossy_path")]
    input: &'a Path,
    band: usize,
    /// The geoid the band's heights were converted from (`--vertical-datum`): the mesh's
    /// heights, and the bound, are above the WGS84 ellipsoid; `null` for the band's own.
    vertical_datum: Option<String>,
    width: u32,
    height: u32,
    valid_samples: u64,
    /// Bands in the file (the one meshed is `band`).
    band_count: usize,
    /// Other bands meshed with it (`--bands`), listed in the report's `variables`.
    #[serde(skip)]
    variable_count: usize,
    /// Valid samples that are not a corner of any valid cell: not in the domain, so not
    /// meshed (and not checked).
    isolated_samples: u64,
    max_error: Option<f64>,
    max_triangles: Option<usize>,
    max_vertices: Option<usize>,
    error_model: &'static str,
    selection: &'static str,
    order: &'static str,
    retriangulate: &'static str,
    /// As asked (`auto` picks the strips or the RTIN; `start_vertices` says how many).
    initial_mesh: &'static str,
    max_edge_length: Option<u32>,
    dp_max_ring: u16,
    flip_rounds: usize,
    extend_rounds: usize,
    vertex_heights: &'static str,
    contour_interval: Option<f64>,
    contour_offset: Option<f64>,
    contour_levels: &'a [f64],
    pixel_coords: bool,
    triangles_before: u64,
    triangles_after: u64,
    vertices_before: u64,
    vertices_after: u64,
    decimation_percent: f64,
    max_error_bound: f64,
    measured_max_error: f64,
    #[serde(serialize_with = "lossy_path")]
    output: &'a Path,
}

/// A path as JSON text, bytes that are not UTF-8 replaced by U+FFFD (serde refuses such a
/// path, which failed the run after its outputs were written).
fn lossy_path<S: serde::Serializer>(path: &&Path, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(&path.to_string_lossy())
}

/// Counts and errors of a finished run, for [`MeshSummary::new`].
pub struct Outcome {
    /// Raster columns and rows.
    pub size: (u32, u32),
    /// Valid samples of the band.
    pub valid_samples: u64,
    /// Bands in the file.
    pub band_count: usize,
    /// Full-grid triangles and domain samples.
    pub before: (u64, u64),
    /// Triangles and vertices written.
    pub after: (u64, u64),
    /// The largest bound the decimation kept.
    pub max_error_bound: f64,
    /// The error the verifier measured.
    pub measured_max_error: f64,
    /// Whether the decimation raised the vertex heights
    /// ([`tinsmith_core::DecimationOptions::raises_vertex_heights`]).
    pub vertex_heights_raised: bool,
}

impl<'a> MeshSummary<'a> {
    /// The summary of a run of `job` that wrote `output`.
    pub fn new(job: &'a MeshJob, output: &'a Path, outcome: Outcome) -> MeshSummary<'a> {
        let (triangles_before, vertices_before) = outcome.before;
        let (triangles_after, vertices_after) = outcome.after;
        let choices = &job.decimation;
        MeshSummary {
            input: &job.input,
            band: job.band,
            vertical_datum: job.vertical_datum.as_ref().map(|d| d.label()),
            isolated_samples: outcome.valid_samples.saturating_sub(vertices_before),
            band_count: outcome.band_count,
            variable_count: job.variables.len(),
            width: outcome.size.0,
            height: outcome.size.1,
            valid_samples: outcome.valid_samples,
            max_error: choices.max_error,
            max_triangles: choices.max_triangles,
            max_vertices: choices.max_vertices,
            error_model: choices.error_model.name(),
            selection: choices.selection.name(),
            // A count target always removes in greedy order (see `with_max_triangles`).
            order: choices.effective_order().name(),
            retriangulate: choices.retriangulate.name(),
            initial_mesh: choices.initial_mesh.name(),
            max_edge_length: choices.max_edge_length,
            dp_max_ring: choices.dp_max_ring,
            flip_rounds: choices.flip_rounds,
            extend_rounds: choices.extend_rounds,
            // As they came out: raised only where decimation raises them.
            vertex_heights: if outcome.vertex_heights_raised {
                VertexHeights::Raised.name()
            } else {
                VertexHeights::Samples.name()
            },
            contour_interval: choices.contour_interval,
            contour_offset: choices.contour_offset,
            contour_levels: &choices.contour_levels,
            pixel_coords: job.pixel_coords,
            triangles_before,
            triangles_after,
            vertices_before,
            vertices_after,
            decimation_percent: 100.0
                * (1.0 - triangles_after as f64 / triangles_before.max(1) as f64),
            max_error_bound: outcome.max_error_bound,
            measured_max_error: outcome.measured_max_error,
            output,
        }
    }

    /// The one-line summary on stderr: triangles before and after, measured error and bound,
    /// with `how` (e.g. the tiling) after the percentage.
    pub fn print(&self, how: &str, feedback: &dyn Feedback) {
        feedback.note(&format!(
            "{}: {} -> {} triangles ({:.1}% decimated){how}, measured max error {}{}",
            self.output.display(),
            self.triangles_before,
            self.triangles_after,
            self.decimation_percent,
            readable(self.measured_max_error),
            match self.max_error {
                Some(e) => format!(" <= {}", readable(e)),
                None => " (no bound asked)".into(),
            }
        ));
        let short = [
            ("--max-triangles", self.max_triangles, self.triangles_after),
            ("--max-vertices", self.max_vertices, self.vertices_after),
        ];
        for (flag, target, reached) in short {
            if let Some(target) = target.filter(|&t| reached > t as u64) {
                let why = match (self.max_error, self.max_edge_length) {
                    (Some(e), None) => {
                        format!("--max-error {} stopped the decimation first", readable(e))
                    }
                    (Some(e), Some(l)) => format!(
                        "--max-error {} or --max-edge-length {l} stopped the decimation first",
                        readable(e)
                    ),
                    (None, Some(l)) => {
                        format!("--max-edge-length {l} keeps them (no edge may be longer)")
                    }
                    (None, None) => {
                        "the domain's outline needs them (its corners are never removed)".into()
                    }
                };
                feedback.note(&format!(
                    "{}: note: {reached} is above {flag} {target}: {why}",
                    self.output.display()
                ));
            }
        }
        if self.band_count > 1 && self.variable_count == 0 {
            feedback.note(&format!(
                "{}: note: meshed band {} of {} (--band picks another)",
                self.input.display(),
                self.band,
                self.band_count
            ));
        }
        if self.isolated_samples > 0 {
            feedback.note(&format!(
                "{}: note: {} valid samples are in no 2x2 block of valid samples, so no \
                 triangle can hold them; they are not in the mesh",
                self.input.display(),
                self.isolated_samples
            ));
        }
    }
}

/// Seconds per phase; in tiled mode the phases are summed over tiles (thread-seconds) and
/// `total` is wall-clock.
#[derive(Debug, Serialize)]
pub struct Seconds {
    pub read: f64,
    pub initial_mesh: f64,
    pub decimate: f64,
    pub verify: f64,
    pub write: f64,
    pub total: f64,
}

/// Notes when heights as large as `heights` leave decimation
/// noticeably less than `bound`: it keeps `2^-40` of the largest |height| as a margin for
/// the rounding of its arithmetic (see `tinsmith_core::effective_limit`), 0.9 at 1e12.
/// The bound is kept either way; the mesh just keeps more triangles than the bound needs.
pub fn note_rounding_margin(
    input: &Path,
    bound: f64,
    heights: Option<(f64, f64)>,
    feedback: &dyn Feedback,
) {
    let Some((lo, hi)) = heights else { return };
    let max_abs = lo.abs().max(hi.abs());
    let limit = tinsmith_core::effective_limit(bound, max_abs);
    // Beyond MAX_ABS_HEIGHT the run is refused, which says enough.
    if !(bound.is_finite() && bound > 0.0)
        || bound - limit <= 0.01 * bound
        || max_abs > tinsmith_core::MAX_ABS_HEIGHT
    {
        return;
    }
    feedback.note(&format!(
        "{}: heights up to {} leave decimation about {:.3e} of the bound {} (the rest is \
         a margin for rounding, 2^-40 of the largest |height|): more triangles are kept \
         than the bound needs; subtracting a constant offset from the heights would give \
         it all",
        input.display(),
        readable(max_abs),
        limit,
        readable(bound)
    ));
}
