//! The decimation driver: builds the start, removes vertices in the chosen order (the
//! paper's sweeps, §3.1, by default) and extracts the TIN.

pub(crate) mod order;
mod remover;
mod rounding;
mod start;

use std::time::Instant;

use order::{greedy, sweep, Stats, Target};
use remover::remove_border;
pub(crate) use remover::Remover;
pub use rounding::{effective_limit, vertex_raise, MAX_ABS_HEIGHT, RAISED_HEIGHT_SHARE};
use start::{
    coarse_start, resolved_start, target_triangles, COUNT_START_FACTOR, COUNT_START_MIN_TRIANGLES,
};

use crate::hole::Rules;
use crate::mesh::Mesh;
use crate::rtin::rtin_for_count;
use crate::EdgeLimit;
use crate::{
    DecimationOptions, Error, ErrorModel, Grid, InitialMesh, Order, Result, Tin, TinVertex,
};

/// A decimated mesh and what it took to get there.
#[derive(Debug, Clone)]
pub struct Decimation {
    /// The decimated TIN.
    pub tin: Tin,
    /// Counts and timings.
    pub report: DecimationReport,
}

/// What a decimation run reached.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DecimationReport {
    /// Vertices of the full mesh: the domain samples (corners of valid cells).
    pub initial_vertices: usize,
    /// Triangles of the full mesh (two per valid cell).
    pub initial_triangles: usize,
    /// Vertices of the mesh decimation started from (fewer than `initial_vertices` unless
    /// the start is [`crate::InitialMesh::Full`]).
    pub start_vertices: usize,
    /// Vertices kept.
    pub final_vertices: usize,
    /// Triangles kept.
    pub final_triangles: usize,
    /// Largest error bound of any kept triangle: an upper bound on the true error.
    pub max_bound: f64,
    /// Sweeps over the candidate vertices until none could be removed; the greedy order
    /// counts as one more.
    pub sweeps: usize,
    /// Removal attempts (vertex retriangulations tried).
    pub attempts: usize,
    /// Seconds spent building the initial mesh.
    pub seconds_initial_mesh: f64,
    /// Seconds spent removing vertices.
    pub seconds_decimation: f64,
}

/// Decimates `grid` into a TIN whose linear interpolation is within
/// `options.max_error` of every domain sample.
///
/// Decimation starts from `options.initial_mesh`: by default a coarse start already within
/// the bound (greedy insertion where few samples stay, else strips, or the RTIN where it
/// is cheap); the paper's start,
/// [`crate::InitialMesh::Full`], splits every valid cell into two triangles. Vertices are
/// then removed as in the paper: classify (§3.2); bound the new triangles' errors
/// (`options.error_model`: by default the exact error over the samples each covers; the
/// paper's propagated bounds, §3.3, with [`ErrorModel::Bounds`]); retriangulate the hole
/// (`options.retriangulation`: by default the triangulation of least maximum error by
/// dynamic programming, ear selection, §3.4, for larger rings or with
/// [`crate::Retriangulation::Ears`]); in repeated row-major sweeps until a sweep removes
/// nothing, or smallest error first with [`crate::Order::Greedy`] (count targets).
/// Corner vertices are never removed, so the domain is unchanged.
/// [`DecimationOptions::paper`] gives the paper's configuration.
///
/// # Guarantee
/// Every triangle's [`crate::ErrorBound`] bounds the error of every original sample it contains.
/// A removal is accepted only when all new bounds are at most
/// `max_error - max_error * 2^-40 - max|z| * 2^-40`, a slack that covers the rounding of
/// the bound arithmetic; so the true error, measured in `f64`, never exceeds `max_error`.
/// With `max_error` below that slack only vertices whose whole star is flat (every
/// neighbour has the same value) are removed, which is exact; on a grid of
/// [`Grid::integral_heights`] under the exact model an error of 0 is measured exactly, so
/// any exactly planar star may go.
///
/// # Determinism
/// The result depends only on `grid` and `options`.
///
/// # Errors
/// [`Error::InvalidMaxError`] when `max_error` is negative, NaN or infinite;
/// [`Error::HeightsTooLarge`] when some |height| exceeds [`MAX_ABS_HEIGHT`].
pub fn decimate(grid: &Grid, options: &DecimationOptions) -> Result<Decimation> {
    decimate_with_progress(grid, options, &mut |_| {})
}

/// Where a running decimation is, for progress displays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// The sweep under way (1-based); 0 while the start mesh is built.
    pub sweep: usize,
    /// Fraction of the vertices queued for this sweep already tried, in `[0, 1]`.
    pub sweep_fraction: f64,
    /// Vertices removed so far.
    pub removed: usize,
}

/// [`decimate`], calling `progress` now and then: while the start mesh is built (at sweep
/// 0: every 64 lines of the strips' 1-D pass, 16,384 strip triangles measured, 1,024
/// vertices inserted or RTIN tried for a count), at each sweep's start, then every 65,536
/// removal attempts of a sweep or removals of the greedy order. A caller that wants to
/// stop a long run can unwind from it. The result is the same as [`decimate`]'s.
pub fn decimate_with_progress(
    grid: &Grid,
    options: &DecimationOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Decimation> {
    run(grid, options, None, progress)
}

/// Decimates a tile of a larger raster whose outer border is shared with neighbouring
/// tiles and already decided: the TIN's vertices on the grid's outer rows and columns are
/// exactly the valid border samples for which `keep_border(x, y)` is true, plus the grid's
/// four corners.
///
/// The other valid border samples are removed first, each replaced by triangles within the
/// strip of cells along the border, so the error there is the error of the straight border
/// edge that skips them; the caller chooses the kept samples so that this 1-D error is
/// within the bound (see [`effective_limit`]) and so that every sample next to an invalid
/// cell of the border strip is kept. Kept border samples are never removed. The rest of the
/// tile is decimated with `options` (an RTIN initial mesh keeps half cells along the border).
///
/// # Errors
/// [`Error::InvalidMaxError`] as [`decimate`]; [`Error::BorderSample`] when a sample to
/// remove is a corner of the domain or its removal would exceed the bound.
pub fn decimate_with_border(
    grid: &Grid,
    options: &DecimationOptions,
    keep_border: &dyn Fn(u32, u32) -> bool,
    progress: &mut dyn FnMut(Progress),
) -> Result<Decimation> {
    run(grid, options, Some(keep_border), progress)
}

fn run(
    grid: &Grid,
    options: &DecimationOptions,
    keep_border: Option<&dyn Fn(u32, u32) -> bool>,
    progress: &mut dyn FnMut(Progress),
) -> Result<Decimation> {
    let max_error = options.max_error;
    let count_target = options.max_triangles.is_some() || options.max_vertices.is_some();
    if max_error.is_nan() || max_error < 0.0 || (max_error.is_infinite() && !count_target) {
        return Err(Error::InvalidMaxError(max_error));
    }
    let edge_limit = EdgeLimit::new(
        &options.edge_metric,
        options.max_edge_length,
        grid.width(),
        grid.height(),
    )?;
    let max_abs = options
        .max_abs_value
        .unwrap_or_else(|| grid.max_abs_value())
        .max(grid.max_abs_value());
    if max_abs > MAX_ABS_HEIGHT {
        return Err(Error::HeightsTooLarge(max_abs));
    }
    let limit = effective_limit(max_error, max_abs);
    let scaled;
    let grid = if grid.variable_count() > 0 {
        if count_target {
            return Err(Error::VariablesUnsupported(
                "takes an error bound, not a triangle or vertex count",
            ));
        }
        scaled = grid.with_height_limit(limit);
        &scaled
    } else {
        grid
    };
    let raised;
    let grid = if options.raises_vertex_heights(max_abs) {
        raised = grid.with_raised_heights(vertex_raise(max_error, max_abs));
        &raised
    } else {
        grid
    };

    let started = Instant::now();
    // Below the slack only exactly flat stars may go (see `Remover::plan`); the RTIN's
    // measured errors are not exact enough for that, so it starts from the full grid,
    // except on integer heights under the exact model, which are measured exactly at 0
    // (see `Grid::integral_heights`). In border mode the RTIN keeps half cells along the
    // border (see `remove_border`).
    let exact_zero = options.error_model == ErrorModel::Exact && grid.integral_heights();
    let rtin_ok = limit > 0.0 || exact_zero;
    let mut count_start_bound = None;
    let mut border_decided = false;
    // While the start is built, `progress` hears of it now and then at sweep 0.
    let starting = std::cell::RefCell::new(&mut *progress);
    let tick = || {
        (starting.borrow_mut())(Progress {
            sweep: 0,
            sweep_fraction: 0.0,
            removed: 0,
        })
    };
    let mut mesh = match options.initial_mesh {
        // A count target starts from an RTIN refined to a multiple of the count, whatever
        // coarse start was chosen (the strips have no such knob).
        InitialMesh::Rtin | InitialMesh::Strips | InitialMesh::Insert | InitialMesh::Auto
            if count_target && limit > 0.0 =>
        {
            let (corners, bounds, start_bound) = rtin_for_count(
                grid,
                COUNT_START_FACTOR
                    .saturating_mul(target_triangles(options))
                    .max(COUNT_START_MIN_TRIANGLES),
                limit,
                &edge_limit,
                keep_border.is_some(),
                &tick,
            );
            count_start_bound = Some(start_bound);
            if corners.len() < target_triangles(options) {
                // Even the finest RTIN tried has fewer triangles than asked for (a nearly
                // planar grid): the full grid lets the count be met exactly.
                Mesh::from_grid(grid)
            } else {
                Mesh::from_triangles(grid, corners, bounds)
            }
        }
        InitialMesh::Rtin | InitialMesh::Strips | InitialMesh::Insert | InitialMesh::Auto
            if rtin_ok =>
        {
            let start = coarse_start(
                grid,
                resolved_start(options),
                limit,
                &edge_limit,
                keep_border,
                &tick,
            );
            border_decided = start.border_decided;
            Mesh::from_triangles(grid, start.corners, start.bounds)
        }
        _ => Mesh::from_grid(grid),
    };
    let start_vertices = (0..mesh.vertex_slots() as u32)
        .filter(|&v| mesh.contains_vertex(v))
        .count();
    let seconds_initial_mesh = started.elapsed().as_secs_f64();

    let started = Instant::now();
    let rules = Rules {
        grid,
        model: options.error_model,
        selection: options.selection,
        method: options.retriangulation,
        dp_max_ring: options.dp_max_ring,
        limit,
        edge_limit: &edge_limit,
        levels: options.contour_levels.as_deref(),
    };
    let mut remover = Remover::new(rules);
    // Shaped for contours to a bound (not a count): a removal whose new triangles span
    // more levels than the old ones would add contour segments, so it is not made.
    remover.segments_may_not_grow = rules.levels.is_some() && !count_target;
    let mut stats = Stats::default();
    if let Some(keep) = keep_border {
        if !border_decided {
            remove_border(&mut mesh, &mut remover, keep)?;
        }
        remover.locked_border = Some((grid.width(), grid.height()));
    }
    match options.order {
        Order::Sweep => sweep(&mut mesh, &mut remover, &mut stats, progress, None),
        Order::Greedy => {
            let target = Target {
                triangles: options.max_triangles,
                vertices: options.max_vertices,
            };
            if let Some(bound) = count_start_bound {
                // A count target first sweeps within its start's bound: those removals
                // cost the greedy order a heap and six re-planned neighbours each, and
                // it would make them first anyway (they are the cheapest). Measured: the
                // same or lower error in half the time.
                remover.rules.limit = bound.min(limit);
                let stop = Some((target, start_vertices));
                sweep(&mut mesh, &mut remover, &mut stats, progress, stop);
                remover.rules.limit = limit;
            }
            greedy(
                &mut mesh,
                &mut remover,
                &mut stats,
                target,
                start_vertices,
                progress,
            )
        }
    }
    if !count_target {
        for _ in 0..options.extend_rounds {
            let removed = crate::extend::remove_through_extended_holes(
                &mut mesh,
                &mut remover,
                progress,
                stats.sweeps,
                stats.removed,
            );
            if removed == 0 {
                break;
            }
            stats.removed += removed;
            sweep(&mut mesh, &mut remover, &mut stats, progress, None);
        }
        for _ in 0..options.flip_rounds {
            if crate::flips::flip_for_error(&mut mesh, &rules) == 0 {
                break;
            }
            sweep(&mut mesh, &mut remover, &mut stats, progress, None);
        }
    }
    if let Some(levels) = rules.levels {
        crate::levels::flip_for_levels(&mut mesh, &rules, levels);
    }
    #[cfg(debug_assertions)]
    mesh.check_invariants();
    let seconds_decimation = started.elapsed().as_secs_f64();

    let (tin, stored_max_bound) = extract(mesh, grid);
    // Every live triangle's bound was at most `limit` when computed in f64; storage in f32
    // rounds it up, so the stored maximum may sit a hair above the limit.
    let max_bound = stored_max_bound.min(limit);
    let report = DecimationReport {
        initial_vertices: grid.domain_sample_count(),
        initial_triangles: 2 * grid.valid_cell_count(),
        start_vertices,
        final_vertices: tin.vertices.len(),
        final_triangles: tin.triangles.len(),
        max_bound,
        sweeps: stats.sweeps,
        attempts: stats.attempts,
        seconds_initial_mesh,
        seconds_decimation,
    };
    Ok(Decimation { tin, report })
}

/// The mesh's live vertices (row-major) and triangles (slot order), and the largest bound.
fn extract(mesh: Mesh<'_>, grid: &Grid) -> (Tin, f64) {
    let max_bound = mesh
        .live_triangles()
        .fold(0.0f64, |m, (t, _)| m.max(mesh.bound(t).max()));
    let (kept, triangles) = mesh.into_numbered();
    // A raised vertex is off its own sample by the raise, which the bounds of triangles
    // never measured (those of the full-grid start) do not hold.
    let max_bound = kept.iter().fold(max_bound, |m, &v| {
        let i = v as usize;
        m.max((grid.vertex_height(i) - grid.values()[i]).abs())
    });
    let width = grid.width();
    let vertices = kept
        .iter()
        .map(|&v| TinVertex {
            x: v % width,
            y: v / width,
            z: grid.vertex_height(v as usize),
        })
        .collect();
    (
        Tin {
            vertices,
            triangles,
        },
        max_bound,
    )
}
