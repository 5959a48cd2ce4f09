//! The decimation driver: the paper's sweep over candidate vertices (§3.1).

use std::collections::BinaryHeap;
use std::time::Instant;

use crate::hole::{Retriangulator, Rules};
use crate::levels::triangle_levels;
use crate::mesh::{CompactBound, Mesh, Star, VertexClass, NONE};
use crate::predicates::Point;
use crate::rtin::{cheap_rtin_with_fewer_triangles, rtin_for_count, rtin_triangles};
use crate::strips::StripPlan;
use crate::{
    DecimationOptions, Error, ErrorBound, ErrorModel, Grid, InitialMesh, Order, Result, Tin,
    TinVertex,
};

/// Relative slack kept below the requested bound so that `f64` rounding in the bound
/// arithmetic can never let a measured error exceed `max_error` (see [`decimate`]).
const ROUNDING_SLACK: f64 = 1.0 / (1u64 << 40) as f64;

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
/// the bound (strips, or the RTIN where it is cheap); the paper's start,
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
/// Every triangle's [`ErrorBound`] bounds the error of every original sample it contains.
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
    /// The sweep under way (1-based).
    pub sweep: usize,
    /// Fraction of the vertices queued for this sweep already tried, in `[0, 1]`.
    pub sweep_fraction: f64,
    /// Vertices removed so far.
    pub removed: usize,
}

/// [`decimate`], calling `progress` now and then (at each sweep's start, then every 65,536
/// removal attempts of a sweep or removals of the greedy order). The result is the same as
/// [`decimate`]'s.
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

/// The bound decimation actually enforces for `max_error` on data whose largest |value| is
/// `max_abs_value`: `max_error` less a slack of `2^-40 (max_error + max_abs_value)` that
/// covers the rounding of the error arithmetic, or 0 when `max_error` is below the slack.
/// A caller that simplifies shared tile borders itself (see [`decimate_with_border`])
/// keeps its 1-D errors within this limit, computed with
/// [`DecimationOptions::max_abs_value`] set to the whole raster's value.
pub fn effective_limit(max_error: f64, max_abs_value: f64) -> f64 {
    let slack = ROUNDING_SLACK * (max_error.min(f64::MAX) + max_abs_value);
    if max_error > slack {
        max_error - slack
    } else {
        0.0
    }
}

/// [`crate::VertexHeights::Raised`] raises a vertex by at most the enforced bound over this (so
/// by less than `max_error / RAISED_HEIGHT_SHARE`; below that, a hair: 2^-24 of the bound
/// plus the largest |height|).
pub const RAISED_HEIGHT_SHARE: f64 = 64.0;

/// How many rounding slacks of [`effective_limit`] a raised vertex sits above its sample
/// (when that is below the bound over [`RAISED_HEIGHT_SHARE`]).
const RAISE_IN_SLACKS: f64 = 65536.0;

/// How far [`crate::VertexHeights::Raised`] puts a vertex above its sample for `max_error` on
/// data whose largest |value| is `max_abs_value`: 2^16 rounding slacks (2^-24 of `max_error
/// + max_abs_value`), at most the enforced bound over [`RAISED_HEIGHT_SHARE`].
///
/// The raise only has to lift a sample exactly the bound above its triangle's plane (ties
/// on integer heights) clear of the slack, which the rounding of any verifier stays far
/// below; it gains the same from 1/64 of the bound down to 2^-20 of it (session 17,
/// docs/results.md). Kept small, it is invisible: a flat lake stays at its level to a
/// fraction of a millimetre, and a bound far beyond the relief does not lift the mesh.
/// It grows with `max_error`, so the raise for a bound also bounds a run's at any smaller
/// one (the float32 formats' rounding margin relies on that).
pub fn vertex_raise(max_error: f64, max_abs_value: f64) -> f64 {
    let slack = ROUNDING_SLACK * (max_error.min(f64::MAX) + max_abs_value);
    (RAISE_IN_SLACKS * slack).min(effective_limit(max_error, max_abs_value) / RAISED_HEIGHT_SHARE)
}

/// The largest |height| decimation accepts: error bounds are stored as `f32`, and between
/// heights up to this they stay well within its range (and planes far from `f64` overflow).
pub const MAX_ABS_HEIGHT: f64 = 1e37;

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
    if let Some(length) = options.max_edge_length {
        if length < 2 {
            return Err(Error::InvalidMaxEdgeLength(length));
        }
    }
    let max_abs = options
        .max_abs_value
        .unwrap_or_else(|| grid.max_abs_value())
        .max(grid.max_abs_value());
    if max_abs > MAX_ABS_HEIGHT {
        return Err(Error::HeightsTooLarge(max_abs));
    }
    let limit = effective_limit(max_error, max_abs);
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
    let mut mesh = match options.initial_mesh {
        // A count target starts from an RTIN refined to a multiple of the count, whatever
        // coarse start was chosen (the strips have no such knob).
        InitialMesh::Rtin | InitialMesh::Strips | InitialMesh::Auto
            if count_target && limit > 0.0 =>
        {
            let (corners, bounds, start_bound) = rtin_for_count(
                grid,
                COUNT_START_FACTOR
                    .saturating_mul(target_triangles(options))
                    .max(COUNT_START_MIN_TRIANGLES),
                limit,
                max_edge_squared(options),
                keep_border.is_some(),
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
        InitialMesh::Rtin | InitialMesh::Strips | InitialMesh::Auto if rtin_ok => {
            let (corners, bounds) = coarse_start(
                grid,
                resolved_start(options),
                limit,
                max_edge_squared(options),
                keep_border.is_some(),
            );
            Mesh::from_triangles(grid, corners, bounds)
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
        max_edge_squared: max_edge_squared(options),
        levels: options.contour_levels.as_deref(),
    };
    let mut remover = Remover::new(rules);
    // Shaped for contours to a bound (not a count): a removal whose new triangles span
    // more levels than the old ones would add contour segments, so it is not made.
    remover.segments_may_not_grow = rules.levels.is_some() && !count_target;
    let mut stats = Stats::default();
    if let Some(keep) = keep_border {
        remove_border(&mut mesh, &mut remover, keep)?;
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

/// The start [`InitialMesh::Auto`] stands for given the other options: with contour
/// levels, the RTIN. The strips' 1-D pass drops samples without regard to the levels,
/// and the level-shaped decimation that follows keeps more segments from them (contour
/// bench, session 14, at ε = interval / 10: Big Tujunga −44 % segments against
/// gdal_contour from the strips, −51 % from the RTIN; becmodel −54 % against −61 %).
fn resolved_start(options: &DecimationOptions) -> InitialMesh {
    match options.initial_mesh {
        InitialMesh::Auto if options.contour_levels.is_some() => InitialMesh::Rtin,
        start => start,
    }
}

/// The triangles and exact errors of a coarse start within `limit`: the RTIN, the strips,
/// or (for [`InitialMesh::Auto`]) the strips unless the RTIN is cheap and has fewer
/// triangles. The strips need edges of any length, so a maximum edge length, or strips
/// refused by their exact measurement (rounding in their 1-D pass), give the RTIN.
fn coarse_start(
    grid: &Grid,
    initial_mesh: InitialMesh,
    limit: f64,
    max_edge_squared: i64,
    full_border: bool,
) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
    let rtin = || rtin_triangles(grid, limit, max_edge_squared, full_border);
    if initial_mesh == InitialMesh::Rtin || max_edge_squared != i64::MAX {
        return rtin();
    }
    let Some(strips) = StripPlan::new(grid, limit, full_border) else {
        return rtin();
    };
    let cheap_rtin = if initial_mesh == InitialMesh::Auto {
        cheap_rtin_with_fewer_triangles(
            grid,
            limit,
            max_edge_squared,
            full_border,
            strips.triangle_count(),
        )
    } else {
        None
    };
    cheap_rtin
        .or_else(|| strips.triangles())
        .unwrap_or_else(rtin)
}

/// A count target's RTIN start has at least this many times the triangles asked for, so
/// that the greedy removal, not the RTIN, picks the last ones to go. Measured (session 4,
/// ETOPO5 to 1 M triangles, Big Tujunga to 100 k): at 4 the error matches or beats the
/// full-grid start (124.5 vs 128; 7 vs 7) in a quarter to half of its time; 2 is twice as
/// fast again but 9–14 % worse; 1 doubles the error.
const COUNT_START_FACTOR: usize = 4;

/// The fewest triangles a count target's RTIN start has besides those the domain's shape
/// forces (or as many as the grid gives), however small the count. For small counts four
/// times is not enough where most of the grid is flat: a CT slice to 300 vertices kept
/// 310.5 from a start of 4 x, 196.5 from 100 k triangles and 194.4 from the full grid; Big
/// Tujunga and becmodel to 300 vertices and 1,000 triangles stay within 3 % of the full
/// grid's error either way (measured before the pre-sweep, which lowers them further).
const COUNT_START_MIN_TRIANGLES: usize = 100_000;

/// The triangles a count target asks for (a mesh of `v` vertices has about `2 v`).
fn target_triangles(options: &DecimationOptions) -> usize {
    let by_vertices = options
        .max_vertices
        .map_or(usize::MAX, |v| v.saturating_mul(2));
    options.max_triangles.unwrap_or(usize::MAX).min(by_vertices)
}

/// The squared maximum edge length, `i64::MAX` when there is none.
fn max_edge_squared(options: &DecimationOptions) -> i64 {
    options
        .max_edge_length
        .map_or(i64::MAX, |l| i64::from(l) * i64::from(l))
}

/// Removes every valid border sample that `keep` rejects (grid corners are kept), in
/// row-major order along each side, with triangles inside the border strip.
fn remove_border(
    mesh: &mut Mesh<'_>,
    remover: &mut Remover<'_>,
    keep: &dyn Fn(u32, u32) -> bool,
) -> Result<()> {
    let (w, h) = (mesh.width(), mesh.height());
    if w >= 3 && h >= 2 {
        // Corner cells get the diagonal through the grid corner, so that no triangle
        // touches two sides and each side's strip is independent of the others.
        for corner in [0, w - 1, (h - 1) * w, h * w - 1] {
            mesh.flip_into_corner(corner);
        }
    }
    let mut border: Vec<(u32, u32)> = Vec::new();
    for x in 1..w.saturating_sub(1) {
        border.push((x, 0));
        if h > 1 {
            border.push((x, h - 1));
        }
    }
    for y in 1..h.saturating_sub(1) {
        border.push((0, y));
        if w > 1 {
            border.push((w - 1, y));
        }
    }
    for (x, y) in border {
        let v = y * w + x;
        if mesh.contains_vertex(v) && !keep(x, y) {
            remover
                .force_remove(mesh, v)
                .map_err(|problem| Error::BorderSample { x, y, problem })?;
        }
    }
    remover.measure_border_fans(mesh)
}

/// The border sample skipped by the fan triangle with these corners that lies farthest
/// from the straight border edge between them (or the triangle's first corner, should no
/// two corners on one side of the grid skip any).
fn skipped_border_sample(mesh: &Mesh<'_>, corners: [u32; 3]) -> [u32; 2] {
    let (w, h) = (mesh.width(), mesh.height());
    let on_one_side = |a: u32, b: u32| {
        let ([xa, ya], [xb, yb]) = ([a % w, a / w], [b % w, b / w]);
        (ya == yb && (ya == 0 || ya == h - 1) && xa.abs_diff(xb) > 1)
            || (xa == xb && (xa == 0 || xa == w - 1) && ya.abs_diff(yb) > 1)
    };
    let side = [(0, 1), (1, 2), (2, 0)]
        .map(|(i, j)| (corners[i].min(corners[j]), corners[i].max(corners[j])))
        .into_iter()
        .find(|&(a, b)| on_one_side(a, b));
    let Some((a, b)) = side else {
        return [corners[0] % w, corners[0] / w];
    };
    let step = if a / w == b / w { 1 } else { w };
    let (za, zb) = (mesh.point(a).z, mesh.point(b).z);
    let n = (b - a) / step;
    let worst = (1..n)
        .map(|k| {
            let line = za + (zb - za) * f64::from(k) / f64::from(n);
            (k, (mesh.point(a + k * step).z - line).abs())
        })
        .fold(
            (1, f64::NEG_INFINITY),
            |best, c| if c.1 > best.1 { c } else { best },
        )
        .0;
    let u = a + worst * step;
    [u % w, u / w]
}

#[derive(Debug, Default)]
struct Stats {
    sweeps: usize,
    attempts: usize,
    removed: usize,
}

/// The paper's sweep, made cheap: a vertex whose star did not change since it last failed
/// would fail again, so each sweep visits only vertices whose star changed, in the same
/// row-major order a full sweep would. With `stop` (a count target and the vertices at the
/// start), it ends as soon as the count is reached.
fn sweep(
    mesh: &mut Mesh<'_>,
    remover: &mut Remover<'_>,
    stats: &mut Stats,
    progress: &mut dyn FnMut(Progress),
    stop: Option<(Target, usize)>,
) {
    let n = mesh.vertex_slots();
    let mut queued = vec![false; n];
    // The sweep in which each vertex last got a large hole beside it (0: none yet).
    let mut beside_large_hole = vec![0u32; n];
    let width = mesh.grid_width();
    let mut this_sweep = AscendingQueue::new(n);
    let mut next_sweep: Vec<u32> = Vec::new();
    for v in 0..n as u32 {
        if mesh.contains_vertex(v) {
            queued[v as usize] = true;
            next_sweep.push(v);
        }
    }
    while !next_sweep.is_empty() {
        stats.sweeps += 1;
        for v in next_sweep.drain(..) {
            this_sweep.insert(v);
        }
        let mut sweep_size = this_sweep.len();
        let mut tried = 0usize;
        progress(Progress {
            sweep: stats.sweeps,
            sweep_fraction: 0.0,
            removed: stats.removed,
        });
        while let Some(v) = this_sweep.pop_min() {
            if beside_large_hole[v as usize] == stats.sweeps as u32 {
                next_sweep.push(v);
                continue;
            }
            queued[v as usize] = false;
            stats.attempts += 1;
            tried += 1;
            if stats.attempts.is_multiple_of(65_536) {
                let sweep_fraction = tried as f64 / sweep_size.max(tried) as f64;
                progress(Progress {
                    sweep: stats.sweeps,
                    sweep_fraction,
                    removed: stats.removed,
                });
            }
            if remover.plan(mesh, v).is_some() {
                remover.apply(mesh, v);
                stats.removed += 1;
                if stop
                    .is_some_and(|(target, initial)| target.reached(mesh, initial, stats.removed))
                {
                    return;
                }
                let large_hole = ring_box_area(&remover.star.ring, width) > LARGE_HOLE_BOX;
                for &u in &remover.star.ring {
                    if large_hole {
                        beside_large_hole[u as usize] = stats.sweeps as u32;
                    }
                    if !queued[u as usize] {
                        queued[u as usize] = true;
                        if u > v {
                            this_sweep.insert(u);
                            sweep_size += 1;
                        } else {
                            next_sweep.push(u);
                        }
                    }
                }
            }
        }
    }
}

/// The vertices around a removed vertex whose hole's bounding box covers more samples than
/// this wait for the next sweep. Where the ground is planar over large areas, removals in
/// one sweep otherwise chain: each one's star holds the triangles the last one made, so
/// the samples measured per removal grow with the chain (a 4000² tilted plane, untiled:
/// 155 s of decimation, 1.7 s with the wait). Waiting lets each sweep remove about every
/// other vertex there, so stars double per sweep instead. Holes this large are rare on real
/// DEMs: six of them at bounds 0.5 to 30 keep the same triangle counts to within 0.01 %,
/// except Fort Worth at 30 (61 triangles, now 68; docs/results.md, session 19).
const LARGE_HOLE_BOX: i64 = 128 * 128;

/// The area (in samples) of the bounding box of `ring`'s sample positions.
fn ring_box_area(ring: &[u32], width: usize) -> i64 {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &v in ring {
        let (x, y) = (v as usize % width, v as usize / width);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    (x1.saturating_sub(x0) as i64) * (y1.saturating_sub(y0) as i64)
}

/// A set of vertex slots taken out smallest first: a bit per slot and a cursor below which
/// no bit is set. In a sweep every insertion is above the slot last taken, so the cursor
/// only moves forward and both operations cost O(1) amortized (a heap costs O(log n)).
struct AscendingQueue {
    words: Vec<u64>,
    /// No bit is set in the words before this one.
    cursor: usize,
    len: usize,
}

impl AscendingQueue {
    fn new(slots: usize) -> AscendingQueue {
        AscendingQueue {
            words: vec![0; slots.div_ceil(64)],
            cursor: 0,
            len: 0,
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn insert(&mut self, v: u32) {
        let (word, bit) = (v as usize / 64, v % 64);
        let mask = 1u64 << bit;
        if self.words[word] & mask == 0 {
            self.words[word] |= mask;
            self.len += 1;
        }
        self.cursor = self.cursor.min(word);
    }

    /// Takes the smallest slot.
    fn pop_min(&mut self) -> Option<u32> {
        if self.len == 0 {
            return None;
        }
        while self.words[self.cursor] == 0 {
            self.cursor += 1;
        }
        let word = self.words[self.cursor];
        self.words[self.cursor] = word & (word - 1);
        self.len -= 1;
        Some((self.cursor * 64) as u32 + word.trailing_zeros())
    }
}

/// When a count-driven decimation stops.
#[derive(Debug, Clone, Copy)]
struct Target {
    triangles: Option<usize>,
    vertices: Option<usize>,
}

impl Target {
    /// Whether `mesh` is down to every count given (never without one), `removed` of its
    /// `initial_vertices` gone.
    fn reached(&self, mesh: &Mesh<'_>, initial_vertices: usize, removed: usize) -> bool {
        if self.triangles.is_none() && self.vertices.is_none() {
            return false;
        }
        self.triangles.is_none_or(|t| mesh.triangle_count() <= t)
            && self
                .vertices
                .is_none_or(|t| initial_vertices - removed <= t)
    }
}

/// A removal candidate: its cost, then the vertex, so ties go to the lower index.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Candidate {
    cost: f64,
    vertex: u32,
    version: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        // Reversed: BinaryHeap is a max-heap and we want the smallest cost first.
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.vertex.cmp(&self.vertex))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// Greedy order: always remove the vertex whose best retriangulation has the smallest
/// error. A key goes stale when a neighbour's removal changes the vertex's star; stale
/// keys are recognised by a per-vertex version and recomputed when popped.
fn greedy(
    mesh: &mut Mesh<'_>,
    remover: &mut Remover<'_>,
    stats: &mut Stats,
    target: Target,
    initial_vertices: usize,
    progress: &mut dyn FnMut(Progress),
) {
    let n = mesh.vertex_slots();
    let mut version = vec![0u32; n];
    let mut heap = BinaryHeap::new();
    // After a count target's first sweeps, if any.
    stats.sweeps += 1;
    let sweep = stats.sweeps;
    progress(Progress {
        sweep,
        sweep_fraction: 0.0,
        removed: stats.removed,
    });
    for v in 0..n as u32 {
        if mesh.contains_vertex(v) {
            stats.attempts += 1;
            if let Some(cost) = remover.plan(mesh, v) {
                heap.push(Candidate {
                    cost,
                    vertex: v,
                    version: 0,
                });
            }
        }
    }
    // For the progress fraction: a count target's removals are known up front (each one
    // takes two triangles away); a bound's are not, so they count against all vertices.
    let expected_removals = match (target.vertices, target.triangles) {
        (Some(v), _) => initial_vertices.saturating_sub(v),
        (None, Some(t)) => mesh.triangle_count().saturating_sub(t) / 2,
        (None, None) => initial_vertices,
    }
    .max(1);
    let reached = |mesh: &Mesh<'_>, removed: usize| target.reached(mesh, initial_vertices, removed);
    while let Some(c) = heap.pop() {
        if reached(mesh, stats.removed) {
            break;
        }
        let v = c.vertex;
        if c.version != version[v as usize] || !mesh.contains_vertex(v) {
            continue;
        }
        stats.attempts += 1;
        let Some(cost) = remover.plan(mesh, v) else {
            continue;
        };
        debug_assert_eq!(cost.to_bits(), c.cost.to_bits(), "a current key is exact");
        remover.apply(mesh, v);
        stats.removed += 1;
        if stats.removed.is_multiple_of(65_536) {
            let sweep_fraction = (stats.removed as f64 / expected_removals as f64).min(1.0);
            progress(Progress {
                sweep,
                sweep_fraction,
                removed: stats.removed,
            });
        }
        for i in 0..remover.star.ring.len() {
            let u = remover.star.ring[i];
            version[u as usize] = version[u as usize].wrapping_add(1);
            stats.attempts += 1;
            if let Some(cost) = remover.plan(mesh, u) {
                heap.push(Candidate {
                    cost,
                    vertex: u,
                    version: version[u as usize],
                });
            }
        }
        // plan() for the neighbours replaced the star; restore nothing: apply() is done.
    }
}

/// The largest hole (ring vertices) decimation retriangulates; vertices with more
/// neighbours stay. Removing a line of vertices one after another can hand each one's hole
/// on to the next, so rings grow with the line and ear clipping, cubic in the ring, took
/// most of the time (ETOPO5 at 100 m in tiles of 2048: rings up to 706, 25.6 s; capped at
/// 64: 8.8 s). Measured on ETOPO5, Big Tujunga, a CT slice and Vinschgau at 5 to 100: the
/// cap changes triangle counts by at most 0.002 %.
const MAX_HOLE_RING: usize = 64;

/// Removes single vertices; holds the buffers reused across attempts.
pub(crate) struct Remover<'g> {
    star: Star,
    ring_star: Star,
    hole: Retriangulator,
    points: Vec<Point>,
    bounds: Vec<ErrorBound>,
    new_triangles: Vec<(u32, [u32; 3], ErrorBound)>,
    pub(crate) rules: Rules<'g>,
    /// In border mode, `(width, height)`: samples on the grid's outer border stay.
    locked_border: Option<(u32, u32)>,
    /// Vertices with more neighbours than this are not tried (see [`MAX_HOLE_RING`]).
    max_ring: usize,
    /// With contour levels: refuse a removal whose new triangles span more levels in all
    /// than the star's did (it would give the contour lines more segments).
    segments_may_not_grow: bool,
    /// Slots of border-fan triangles made by [`Remover::force_remove`] whose errors are
    /// measured once the border is done ([`Remover::measure_border_fans`]): along a run of
    /// skipped border samples each fan's last triangle spans the whole run so far and is
    /// replaced by the next removal, so measuring it each time would be quadratic.
    unmeasured_fans: Vec<u32>,
}

impl<'g> Remover<'g> {
    fn new(rules: Rules<'g>) -> Remover<'g> {
        Remover {
            star: Star::default(),
            ring_star: Star::default(),
            hole: Retriangulator::default(),
            points: Vec::new(),
            bounds: Vec::new(),
            new_triangles: Vec::new(),
            rules,
            locked_border: None,
            max_ring: MAX_HOLE_RING,
            segments_may_not_grow: false,
            unmeasured_fans: Vec::new(),
        }
    }

    /// Removes border sample `v` whatever the error. A fan's triangles are measured and
    /// checked against the limit by [`Remover::measure_border_fans`]; any other hole's
    /// triangles are measured and checked here.
    fn force_remove(
        &mut self,
        mesh: &mut Mesh<'_>,
        v: u32,
    ) -> std::result::Result<(), &'static str> {
        let limit = self.rules.limit;
        if self.plan_border_fan(mesh, v) {
            self.unmeasured_fans
                .extend(self.new_triangles.iter().map(|t| t.0));
            self.apply(mesh, v);
            return Ok(());
        }
        let saved = self.rules;
        let exact_zero = self.exact_zero();
        self.rules = Rules {
            model: crate::ErrorModel::Exact,
            selection: crate::EdgeSelection::MinError,
            method: crate::Retriangulation::Ears,
            // Exactly planar holes only, decided exactly, at a bound of 0 on integer heights.
            limit: if exact_zero { 0.0 } else { f64::INFINITY },
            // The caller's 1-D rule already spaced the kept border samples.
            max_edge_squared: i64::MAX,
            ..saved
        };
        self.max_ring = usize::MAX;
        let planned = self.plan(mesh, v);
        self.max_ring = MAX_HOLE_RING;
        self.rules = saved;
        match planned {
            None => Err("it is a corner of the domain, or its hole has no triangulation"),
            Some(worst) if worst > limit => Err("skipping it exceeds the error bound"),
            Some(_) => {
                self.apply(mesh, v);
                Ok(())
            }
        }
    }

    /// Whether errors are decided exactly at 0: a bound of 0 under the exact model on a grid
    /// of [`Grid::integral_heights`].
    fn exact_zero(&self) -> bool {
        self.rules.limit == 0.0
            && self.rules.model == ErrorModel::Exact
            && self.rules.grid.integral_heights()
    }

    /// Plans the removal of border vertex `v` as a fan from its border neighbour that comes
    /// first along the border (already settled: kept, since border samples are removed in
    /// order). The next border vertex then keeps a small star, so a long run of removals
    /// stays linear. Returns false when `v` is not a boundary vertex or the fan is not a
    /// valid triangulation of the hole. The new triangles' bounds are placeholders until
    /// [`Remover::measure_border_fans`] measures them.
    fn plan_border_fan(&mut self, mesh: &Mesh<'_>, v: u32) -> bool {
        let star = &mut self.ring_star;
        mesh.star(v, star);
        if mesh.classify(v, star) != VertexClass::Boundary {
            return false;
        }
        self.points.clear();
        self.points.extend(star.ring.iter().map(|&u| mesh.point(u)));
        let m = self.points.len();
        let (first, last) = (&self.points[0], &self.points[m - 1]);
        let apex = if first.x + first.y <= last.x + last.y {
            0
        } else {
            m - 1
        };
        // The other ring vertices, in order: the apex is the first or the last.
        let others = if apex == 0 { 1..m } else { 0..m - 1 };
        self.new_triangles.clear();
        for ((p, q), &slot) in others.clone().zip(others.skip(1)).zip(&star.triangles) {
            let [a, b, c] = [apex, p, q].map(|i| self.points[i]);
            if crate::predicates::orient(&a, &b, &c) <= 0 {
                return false;
            }
            let corners = [apex, p, q].map(|i| star.ring[i]);
            // Measured later, by `measure_border_fans`.
            let unmeasured = ErrorBound {
                above: 0.0,
                below: 0.0,
            };
            self.new_triangles.push((slot, corners, unmeasured));
        }
        true
    }

    /// Measures the exact errors of the border-fan triangles [`Remover::force_remove`] made
    /// that are still in the mesh, stores them as their bounds, and checks them against
    /// the limit (at a bound of 0 on integer heights, planarity is decided exactly, as in
    /// `plan`). Each is measured once, so a run of skipped border samples costs time
    /// linear in its length.
    fn measure_border_fans(&mut self, mesh: &mut Mesh<'_>) -> Result<()> {
        let cap = if self.exact_zero() {
            0.0
        } else {
            f64::INFINITY
        };
        let mut slots = std::mem::take(&mut self.unmeasured_fans);
        slots.sort_unstable();
        slots.dedup();
        for t in slots {
            let corners = mesh.corners(t);
            if corners[0] == NONE {
                continue;
            }
            let [a, b, c] = corners.map(|u| mesh.point(u));
            let bound = crate::exact::triangle_error(self.rules.grid, &a, &b, &c, cap)
                .filter(|bound| bound.max() <= self.rules.limit);
            let Some(bound) = bound else {
                let [x, y] = skipped_border_sample(mesh, corners);
                return Err(Error::BorderSample {
                    x,
                    y,
                    problem: "skipping it exceeds the error bound",
                });
            };
            mesh.set_bound(t, bound);
        }
        Ok(())
    }

    /// Plans the removal of `v`: if it is interior or boundary and its hole can be
    /// retriangulated within the limit, returns the largest new bound and keeps the plan
    /// for [`Remover::apply`]. Does not change the mesh.
    pub(crate) fn plan(&mut self, mesh: &Mesh<'_>, v: u32) -> Option<f64> {
        if !mesh.contains_vertex(v) {
            return None;
        }
        if let Some((w, h)) = self.locked_border {
            let (x, y) = (v % w, v / w);
            if x == 0 || y == 0 || x == w - 1 || y == h - 1 {
                return None;
            }
        }
        let star = &mut self.ring_star;
        mesh.star(v, star);
        if star.ring.len() > self.max_ring || mesh.classify(v, star) == VertexClass::Corner {
            return None;
        }
        self.points.clear();
        self.points.extend(star.ring.iter().map(|&u| mesh.point(u)));
        let centre = mesh.sample_point(v);
        if self.rules.limit == 0.0
            && !(self.rules.model == ErrorModel::Exact && self.rules.grid.integral_heights())
            && self.points.iter().any(|p| p.z != centre.z)
        {
            // Below the rounding slack only exactly flat stars go: their bound arithmetic
            // is exact (all differences are zero). Integer heights under the exact model
            // are measured exactly at 0 (see `Grid::integral_heights`), so any star may.
            return None;
        }
        // Any retriangulation interpolates the centre from ring values, so a centre further
        // than the limit outside their range can never go (a cheap exact rejection).
        let (lo, hi) = self
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.z), hi.max(p.z))
            });
        if centre.z - hi > self.rules.limit || lo - centre.z > self.rules.limit {
            return None;
        }
        self.bounds.clear();
        self.bounds
            .extend(star.triangles.iter().map(|&t| mesh.bound(t)));
        self.hole.load(centre, &self.points, &self.bounds);
        let (triangles, worst) = self.hole.retriangulate(&self.rules)?;
        if let Some(levels) = self.rules.levels.filter(|_| self.segments_may_not_grow) {
            let m = self.points.len();
            let before: usize = (0..star.triangles.len())
                .map(|i| {
                    triangle_levels(levels, &centre, &self.points[i], &self.points[(i + 1) % m])
                })
                .sum();
            let after: usize = triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.corners.map(|k| &self.points[k as usize]);
                    triangle_levels(levels, a, b, c)
                })
                .sum();
            if after > before {
                return None;
            }
        }
        self.new_triangles.clear();
        for (tri, &slot) in triangles.iter().zip(&star.triangles) {
            let corners = tri.corners.map(|i| star.ring[i as usize]);
            self.new_triangles.push((slot, corners, tri.bound));
        }
        Some(worst)
    }

    /// Carries out the last successful [`Remover::plan`], which must have been for `v`
    /// with the mesh unchanged since; afterwards `self.star` holds `v`'s former star.
    pub(crate) fn apply(&mut self, mesh: &mut Mesh<'_>, v: u32) {
        std::mem::swap(&mut self.star, &mut self.ring_star);
        mesh.replace_star(v, &self.star, &self.new_triangles);
        #[cfg(test)]
        mesh.check_invariants();
    }
}
/// The mesh's live vertices (row-major) and triangles (slot order), and the largest bound.
fn extract(mesh: Mesh<'_>, grid: &Grid) -> (Tin, f64) {
    let max_bound = mesh
        .live_triangles()
        .fold(0.0f64, |m, (t, _)| m.max(mesh.bound(t).max()));
    let (kept, triangles) = mesh.into_numbered();
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
