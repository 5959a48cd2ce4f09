//! `tinsmith.mesh`: decimate a grid in memory, verify the TIN independently, hand it to
//! Python; the same engine calls as `tinsmith mesh` (untiled up to `tile_size` samples a
//! side or with a count target, tiled beyond), with the GIL released.

use std::time::Instant;

use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tinsmith_core::{decimate_with_progress, Grid};
use tinsmith_georef::Placement;
use tinsmith_tiling::{mesh_tiles, GridSource, MeshCollector, TileOptions};

use crate::choices::MeshChoices;
use crate::interrupt::Interruptible;
use crate::tin::{Georef, Tin};

/// What the engine hands back, before it becomes Python objects.
struct Meshed {
    /// Vertices in file coordinates, triangles oriented for them.
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    report: Vec<(&'static str, ReportValue)>,
    measured_max_error: f64,
}

/// A report field's value.
enum ReportValue {
    Int(u64),
    Float(f64),
    OptFloat(Option<f64>),
    OptInt(Option<u64>),
    Text(&'static str),
    Bool(bool),
    Floats(Vec<f64>),
    Dict(Vec<(&'static str, ReportValue)>),
}

impl ReportValue {
    fn into_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(match self {
            ReportValue::Int(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::Float(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::OptFloat(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::OptInt(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::Text(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::Bool(v) => v.into_pyobject(py)?.to_owned().into_any(),
            ReportValue::Floats(v) => v.into_pyobject(py)?.into_any(),
            ReportValue::Dict(fields) => dict(py, fields)?.into_any(),
        })
    }
}

fn dict<'py>(
    py: Python<'py>,
    fields: Vec<(&'static str, ReportValue)>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in fields {
        d.set_item(k, v.into_py(py)?)?;
    }
    Ok(d)
}

/// The Rust side of `tinsmith.mesh` (the Python wrapper normalises the arguments; see
/// `python/tinsmith/__init__.py`).
#[pyfunction]
#[pyo3(signature = (heights, choices, nodata=None, mask=None, transform=None))]
pub fn mesh<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    choices: &Bound<'py, PyDict>,
    nodata: Option<f64>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    transform: Option<[f64; 6]>,
) -> PyResult<Tin> {
    let total = Instant::now();
    let choices = crate::choices_from_dict(choices)?;
    if let Some(e) = choices.decimation.max_error {
        if !(e.is_finite() && e >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "max_error must be a finite number >= 0, got {e}"
            )));
        }
    }
    if choices.tile_size < 2 {
        return Err(PyValueError::new_err(format!(
            "tile_size must be at least 2, got {}",
            choices.tile_size
        )));
    }
    let (rows, columns) = crate::heights::shape(heights)?;
    let fits = columns <= choices.tile_size as usize && rows <= choices.tile_size as usize;
    let count_target = choices.decimation.has_count_target();
    if !fits && !count_target && choices.decimation.max_error.is_none() {
        return Err(PyValueError::new_err("tiles need max_error"));
    }
    // Refused before the grid is allocated: the CLI's measured need of a whole-grid run or
    // a count target; for the tiled engine the grid itself (8 bytes a sample) and as much
    // again for its caches and the welded mesh (an allowance, not a measurement: the
    // tiles' own working memory is bounded by the tile size).
    let (per_sample, extra) = if count_target {
        let samples = (rows * columns) as u64;
        let start = choices.decimation.count_target_start_triangles(samples);
        (
            tinsmith_tiling::COUNT_TARGET_BYTES_PER_SAMPLE,
            start.saturating_mul(tinsmith_tiling::BYTES_PER_START_TRIANGLE),
        )
    } else if fits {
        (tinsmith_tiling::WHOLE_GRID_BYTES_PER_SAMPLE, 0)
    } else {
        (16, 0)
    };
    crate::heights::check_fits(columns as u64, rows as u64, per_sample, extra, "meshing")?;
    let georef = Georef::new(transform, columns as u32, rows as u32)?;

    let samples = crate::heights::read(heights, nodata, mask.as_ref())?;
    let in_place = samples.is_shared();
    let grid = Grid::from_samples(samples);
    let heights_range = valid_range(&grid);
    let georef = georef.with_heights(heights_range);
    let bound = decimation_bound(
        &grid,
        &choices,
        &georef,
        heights_range,
        fits || count_target,
    )?;
    let options = choices.decimation_options(bound, heights_range)?;
    let placement = georef.placement();

    let interrupt = Interruptible::new();
    let meshed = py.detach(|| -> Result<Meshed, crate::Failure> {
        if fits || count_target {
            untiled(&grid, &options, &choices, placement, &interrupt, total)
        } else {
            tiled(&grid, &options, &choices, placement, &interrupt, total)
        }
    });
    let mut meshed = interrupt.finish(py, meshed)?;
    meshed
        .report
        .push(("heights_in_place", ReportValue::Bool(in_place)));
    let report = dict(py, meshed.report)?;
    Tin::new(
        py,
        meshed.vertices,
        meshed.triangles,
        meshed.measured_max_error,
        choices.decimation.max_error,
        report,
        georef,
    )
}

/// The bound given to the decimator, as the CLI's `FormatPlan` sets it: `max_error`, less
/// the float32 rounding of the heights when the mesh is for STL or glTF (`format`), so that
/// the file keeps `max_error` (measured at every valid sample when the grid is meshed
/// `whole` with vertices on their samples; bounded from the height range when tiled or
/// when decimation raises the vertices).
fn decimation_bound(
    grid: &Grid,
    choices: &MeshChoices,
    georef: &Georef,
    heights: Option<(f64, f64)>,
    whole: bool,
) -> PyResult<f64> {
    let max_error = choices.decimation.max_error.unwrap_or(f64::INFINITY);
    let Some(format) = choices.format.filter(|f| f.is_float32()) else {
        return Ok(max_error);
    };
    let origin = georef.origin();
    let max_abs = grid.max_abs_value();
    let samples_only = !choices
        .decimation_options(max_error, heights)?
        .raises_vertex_heights(max_abs);
    let rounding = if samples_only && whole {
        origin.height_rounding(grid.values())
    } else {
        let (lo, hi) = heights.unwrap_or((0.0, 0.0));
        let raise = tinsmith_core::vertex_raise(max_error, max_abs);
        origin.height_rounding_bound(lo, hi + raise)
    };
    let bound = max_error - rounding;
    if bound < 0.0 {
        return Err(PyValueError::new_err(format!(
            "max_error {} is smaller than the float32 rounding of the heights ({}) in \
             {format}; use a larger bound or a double-precision format (ply, obj, fgb, \
             geojson, landxml)",
            tinsmith_georef::readable(max_error),
            tinsmith_georef::readable(rounding)
        )));
    }
    Ok(bound)
}

/// The least and largest valid sample, `None` when there is none.
fn valid_range(grid: &Grid) -> Option<(f64, f64)> {
    let mut range: Option<(f64, f64)> = None;
    for &v in grid.values().iter().filter(|v| v.is_finite()) {
        range = Some(range.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
    }
    range
}

/// What a run reached, as the CLI's report counts it.
struct Outcome {
    /// Full-grid triangles and domain samples.
    before: (u64, u64),
    /// Triangles and vertices kept.
    after: (u64, u64),
    /// The largest bound the decimation kept.
    max_bound: f64,
    /// The error the verifier measured.
    measured: f64,
    /// Whether the vertex heights were raised.
    raised: bool,
}

/// The report fields every run has (`tinsmith mesh --report`'s names).
fn summary(
    grid: &Grid,
    choices: &MeshChoices,
    placement: Placement,
    outcome: Outcome,
) -> Vec<(&'static str, ReportValue)> {
    use ReportValue::*;
    let Outcome {
        before,
        after,
        max_bound,
        measured,
        raised,
    } = outcome;
    let valid = grid.valid_count() as u64;
    vec![
        ("width", Int(grid.width().into())),
        ("height", Int(grid.height().into())),
        ("valid_samples", Int(valid)),
        ("isolated_samples", Int(valid.saturating_sub(before.1))),
        ("max_error", OptFloat(choices.decimation.max_error)),
        (
            "max_triangles",
            OptInt(choices.decimation.max_triangles.map(|n| n as u64)),
        ),
        (
            "max_vertices",
            OptInt(choices.decimation.max_vertices.map(|n| n as u64)),
        ),
        ("error_model", Text(choices.decimation.error_model.name())),
        ("selection", Text(choices.decimation.selection.name())),
        ("order", Text(choices.decimation.effective_order().name())),
        (
            "retriangulate",
            Text(choices.decimation.retriangulate.name()),
        ),
        ("initial_mesh", Text(choices.decimation.initial_mesh.name())),
        (
            "max_edge_length",
            OptInt(choices.decimation.max_edge_length.map(u64::from)),
        ),
        ("dp_max_ring", Int(choices.decimation.dp_max_ring.into())),
        ("flip_rounds", Int(choices.decimation.flip_rounds as u64)),
        (
            "extend_rounds",
            Int(choices.decimation.extend_rounds as u64),
        ),
        (
            "vertex_heights",
            Text(if raised {
                tinsmith_core::VertexHeights::Raised.name()
            } else {
                tinsmith_core::VertexHeights::Samples.name()
            }),
        ),
        (
            "contour_interval",
            OptFloat(choices.decimation.contour_interval),
        ),
        (
            "contour_offset",
            OptFloat(choices.decimation.contour_offset),
        ),
        (
            "contour_levels",
            Floats(choices.decimation.contour_levels.clone()),
        ),
        ("pixel_coords", Bool(matches!(placement, Placement::Pixel))),
        ("triangles_before", Int(before.0)),
        ("triangles_after", Int(after.0)),
        ("vertices_before", Int(before.1)),
        ("vertices_after", Int(after.1)),
        (
            "decimation_percent",
            Float(100.0 * (1.0 - after.0 as f64 / before.0.max(1) as f64)),
        ),
        ("max_error_bound", Float(max_bound)),
        ("measured_max_error", Float(measured)),
    ]
}

/// One piece: decimated by `decimate_with_progress`, checked by the verifier.
fn untiled(
    grid: &Grid,
    options: &tinsmith_core::DecimationOptions,
    choices: &MeshChoices,
    placement: Placement,
    interrupt: &Interruptible,
    total: Instant,
) -> Result<Meshed, crate::Failure> {
    if grid.valid_cell_count() == 0 {
        return Err(crate::Failure::Value(
            "heights have no 2x2 block of valid samples, so there is nothing to triangulate".into(),
        ));
    }
    let result =
        interrupt.run(|| decimate_with_progress(grid, options, &mut |_| interrupt.check()))?;
    let result = result.map_err(|e| crate::Failure::Value(e.to_string()))?;
    let tin = &result.tin;
    let max_error = options.max_error;
    let t = Instant::now();
    let check = tinsmith_tiling::check_tin(grid, tin, |_, v| v.z, max_error)
        .map_err(|e| crate::Failure::Bound(e.to_string()))?;
    let verify_seconds = t.elapsed().as_secs_f64();
    if !check.passed() {
        return Err(crate::Failure::Bound(format!(
            "internal error, the decimated mesh failed verification ({})",
            check.problems.join("; ")
        )));
    }
    let (vertices, triangles) = placement.file_mesh(
        tin.vertices().iter().map(|v| (v.x, v.y, v.z)),
        tin.triangles().iter().copied(),
    );
    let r = &result.report;
    let raised = options.raises_vertex_heights(grid.max_abs_value());
    let mut report = summary(
        grid,
        choices,
        placement,
        Outcome {
            before: (r.initial_triangles as u64, r.initial_vertices as u64),
            after: (r.final_triangles as u64, r.final_vertices as u64),
            max_bound: r.max_bound,
            measured: check.max_error,
            raised,
        },
    );
    use ReportValue::*;
    report.extend([
        ("start_vertices", Int(r.start_vertices as u64)),
        ("sweeps", Int(r.sweeps as u64)),
        ("removal_attempts", Int(r.attempts as u64)),
        (
            "seconds",
            Dict(vec![
                ("initial_mesh", Float(r.seconds_initial_mesh)),
                ("decimate", Float(r.seconds_decimation)),
                ("verify", Float(verify_seconds)),
                ("total", Float(total.elapsed().as_secs_f64())),
            ]),
        ),
    ]);
    Ok(Meshed {
        vertices,
        triangles,
        report,
        measured_max_error: check.max_error,
    })
}

/// Tile by tile, on `threads` workers, welded in memory; every tile checked by the
/// verifier inside the engine.
fn tiled(
    grid: &Grid,
    options: &tinsmith_core::DecimationOptions,
    choices: &MeshChoices,
    placement: Placement,
    interrupt: &Interruptible,
    total: Instant,
) -> Result<Meshed, crate::Failure> {
    let raised = options.raises_vertex_heights(grid.max_abs_value());
    let tile_options = TileOptions::new(options.clone())
        .with_tile_size(choices.tile_size)
        .with_threads(choices.threads.map_or(0, |n| n as usize));
    let mut collector = MeshCollector::new();
    let source = GridSource::new(grid);
    let r = interrupt.run(|| {
        mesh_tiles(&source, &tile_options, &mut collector, &mut |_| {
            interrupt.check()
        })
    })?;
    let r = r.map_err(|e| match e {
        tinsmith_tiling::Error::Options(_) | tinsmith_tiling::Error::Heights(_) => {
            crate::Failure::Value(e.to_string())
        }
        other => crate::Failure::Bound(error_chain(&other)),
    })?;
    if r.final_triangles == 0 {
        return Err(crate::Failure::Value(
            "heights have no 2x2 block of valid samples, so there is nothing to triangulate".into(),
        ));
    }
    let (vertices, triangles) = collector.into_parts();
    let (vertices, triangles) = placement.file_mesh(
        vertices.iter().map(|v| (v[0] as u32, v[1] as u32, v[2])),
        triangles,
    );
    let mut report = summary(
        grid,
        choices,
        placement,
        Outcome {
            before: (r.initial_triangles, r.initial_vertices),
            after: (r.final_triangles, r.final_vertices),
            max_bound: r.max_bound,
            measured: r.measured_max_error,
            raised,
        },
    );
    use ReportValue::*;
    report.extend([
        (
            "seconds",
            Dict(vec![
                ("initial_mesh", Float(0.0)),
                ("decimate", Float(r.seconds_decimation)),
                ("verify", Float(r.seconds_verify)),
                ("total", Float(total.elapsed().as_secs_f64())),
            ]),
        ),
        (
            "tiles",
            Dict(vec![
                ("count", Int(r.plan.len() as u64)),
                ("size", Int(r.plan.size().into())),
                ("columns", Int(r.plan.columns().into())),
                ("rows", Int(r.plan.rows().into())),
                ("threads", Int(r.threads as u64)),
                ("welded", Bool(true)),
                ("tiles_seconds", Float(r.seconds_total)),
            ]),
        ),
    ]);
    Ok(Meshed {
        vertices,
        triangles,
        report,
        measured_max_error: r.measured_max_error,
    })
}

/// `error` and its sources, as the CLI prints them (`{:#}`).
pub fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(e) = source {
        text.push_str(": ");
        text.push_str(&e.to_string());
        source = e.source();
    }
    text
}
