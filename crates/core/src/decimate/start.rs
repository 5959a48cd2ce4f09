//! The mesh decimation starts from: which start, and the bound or count it is built to.

use crate::insert::insertion_triangles;
use crate::mesh::CompactBound;
use crate::rtin::{cheap_rtin_with_fewer_triangles, rtin_triangles};
use crate::strips::{estimated_kept, kept_along_rows, StripPlan};
use crate::{DecimationOptions, EdgeLimit, Grid, InitialMesh};

/// The start [`InitialMesh::Auto`] stands for given the other options: with contour
/// levels, the RTIN. The strips' 1-D pass drops samples without regard to the levels,
/// and the level-shaped decimation that follows keeps more segments from them (contour
/// bench at ε = interval / 10: Big Tujunga −44 % segments against
/// gdal_contour from the strips, −51 % from the RTIN; becmodel −54 % against −61 %).
pub(super) fn resolved_start(options: &DecimationOptions) -> InitialMesh {
    match options.initial_mesh {
        InitialMesh::Auto if options.contour_levels.is_some() => InitialMesh::Rtin,
        start => start,
    }
}

/// A coarse start: its triangles and exact errors, and whether its outline is already the
/// decided border of a tile (insertion starts from it; the other starts keep half cells
/// along the border, whose skipped samples removal takes out first).
pub(super) struct Start {
    pub corners: Vec<[u32; 3]>,
    pub bounds: Vec<CompactBound>,
    pub border_decided: bool,
}

/// [`InitialMesh::Auto`] inserts (on a grid without nodata) where the strips keep at most
/// one sample in this many (the strips along rows, where an edge cap rules the strips out), and then only while insertion places fewer vertices
/// than the strips keep; otherwise the strips or the RTIN start. Decided by the input and
/// the options alone, never by time. Measured (one thread, interleaved runs, 2026-12-04;
/// docs/notes/2026-12-04-greedy-insertion-start.md): at ε = 30 insertion then removal took
/// about 0.5 x the strips' time on Big Tujunga's tiles and 0.7 x on Fuji (the strips keep
/// 5 %), but 1-1.7 x on a CT slice (11 %, long flat runs the strips pass cheaply); at ε = 5
/// (a quarter of the samples kept) 1.3-2.5 x; ETOPO5's pyramid 0.32-0.45 x.
pub(super) const AUTO_INSERT_SHARE: usize = 12;

/// Without an edge cap, on a whole raster (not a tile), [`InitialMesh::Auto`] first
/// estimates what the strips keep from every this many lines each way
/// ([`estimated_kept`]); at most 3/4 of the share of [`AUTO_INSERT_SHARE`] it inserts
/// (budget: the estimate), at least 3/2 of it it takes the strips, and in between it plans
/// the strips to count, as before. Where it inserts, the plan was thrown away: 13 % of
/// `mesh`'s instructions on Fuji at ε = 30. The estimate was within 3-24 % of the count on
/// Fuji, a CT slice and Big Tujunga at ε = 1-60, so those decisions are unchanged. Tiles
/// count exactly: on Big Tujunga's pyramid (levels 0-12) the estimate flipped some tiles'
/// starts, for 41,966 -> 43,022 triangles in the same time.
pub(super) const AUTO_LINE_STEP: usize = 8;

/// The triangles and exact errors of a coarse start within `limit`: greedy insertion
/// ([`InitialMesh::Insert`], and for [`InitialMesh::Auto`] where the strips keep few
/// samples, see [`AUTO_INSERT_SHARE`]), the RTIN, the strips, or (for
/// [`InitialMesh::Auto`]) the strips unless the RTIN is cheap and has fewer triangles.
/// Insertion needs a grid without nodata; the strips need edges of any length, so a
/// maximum edge length, or strips refused by their exact measurement (rounding in their
/// 1-D pass), give the RTIN.
pub(super) fn coarse_start(
    grid: &Grid,
    initial_mesh: InitialMesh,
    limit: f64,
    edge_limit: &EdgeLimit,
    keep_border: Option<&dyn Fn(u32, u32) -> bool>,
    tick: &dyn Fn(),
) -> Start {
    let full_border = keep_border.is_some();
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let no_nodata = limit > 0.0
        && matches!(initial_mesh, InitialMesh::Insert | InitialMesh::Auto)
        && grid.valid_cell_count() == w.saturating_sub(1) * h.saturating_sub(1);
    let mut strips = None;
    let budget = match initial_mesh {
        _ if !no_nodata => None,
        InitialMesh::Insert => Some(usize::MAX),
        InitialMesh::Auto => {
            // With an edge cap the strips cannot start, so only their rows are planned
            // (half the pass) to count what they keep. Without one, an estimate from a
            // few lines decides where it is clear (see `AUTO_LINE_STEP`), the plan where
            // it is not (and the plan is kept for the start then).
            let share = w * h / AUTO_INSERT_SHARE;
            if grid.variable_count() > 0 {
                // Several variables: insert where every band alone keeps clearly few
                // samples, within a budget of what they keep alone, summed (about the
                // most a joint mesh keeps). A tile takes the strips, an edge cap the
                // RTIN; both honour every variable.
                (edge_limit.is_none() && !full_border)
                    .then(|| estimated_kept_by_band(grid, limit))
                    .filter(|kept| kept.iter().max() <= Some(&(share - share / 4)))
                    .map(|kept| kept.into_iter().fold(0, usize::saturating_add))
            } else {
                let kept = if !edge_limit.is_none() {
                    Some(kept_along_rows(grid, limit, full_border, tick))
                } else if full_border {
                    // A tile's start is decided by the count itself (see `AUTO_LINE_STEP`).
                    strips = StripPlan::new(grid, limit, full_border, tick);
                    strips.as_ref().map(|s| s.kept_count())
                } else {
                    let estimate = estimated_kept(grid, limit, full_border, AUTO_LINE_STEP);
                    if estimate <= share - share / 4 {
                        Some(estimate)
                    } else if estimate >= share + share / 2 {
                        None
                    } else {
                        strips = StripPlan::new(grid, limit, full_border, tick);
                        strips.as_ref().map(|s| s.kept_count())
                    }
                };
                kept.filter(|&kept| kept.saturating_mul(AUTO_INSERT_SHARE) <= w * h)
            }
        }
        _ => None,
    };
    if let Some(budget) = budget {
        if let Some((corners, bounds)) =
            insertion_triangles(grid, limit, edge_limit, keep_border, budget, tick)
        {
            return Start {
                corners,
                bounds,
                border_decided: full_border,
            };
        }
    }
    let (corners, bounds) = bottom_up_start(
        grid,
        initial_mesh,
        limit,
        edge_limit,
        full_border,
        strips,
        tick,
    );
    Start {
        corners,
        bounds,
        border_decided: false,
    }
}

/// The strips' estimated kept samples ([`estimated_kept`]) of the height and of each
/// constrained variable, each alone.
fn estimated_kept_by_band(grid: &Grid, limit: f64) -> Vec<usize> {
    let height = estimated_kept(&grid.heights_alone(), limit, false, AUTO_LINE_STEP);
    let variables = grid.variables().iter().filter(|v| !v.unconstrained());
    std::iter::once(height)
        .chain(variables.map(|v| estimated_kept(&v.grid, v.own_limit(), false, AUTO_LINE_STEP)))
        .collect()
}

/// The RTIN or the strips (see [`coarse_start`]).
fn bottom_up_start(
    grid: &Grid,
    initial_mesh: InitialMesh,
    limit: f64,
    edge_limit: &EdgeLimit,
    full_border: bool,
    strips: Option<StripPlan<'_>>,
    tick: &dyn Fn(),
) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
    let rtin = || rtin_triangles(grid, limit, edge_limit, full_border);
    if initial_mesh == InitialMesh::Rtin || !edge_limit.is_none() {
        return rtin();
    }
    let Some(strips) = strips.or_else(|| StripPlan::new(grid, limit, full_border, tick)) else {
        return rtin();
    };
    let cheap_rtin = if initial_mesh != InitialMesh::Strips {
        cheap_rtin_with_fewer_triangles(
            grid,
            limit,
            edge_limit,
            full_border,
            strips.triangle_count(),
        )
    } else {
        None
    };
    cheap_rtin
        .or_else(|| strips.triangles(edge_limit, tick))
        .unwrap_or_else(rtin)
}

/// A count target's RTIN start has at least this many times the triangles asked for, so
/// that the greedy removal, not the RTIN, picks the last ones to go. Measured (ETOPO5 to 1 M triangles, Big Tujunga to 100 k): at 4 the error matches or beats the
/// full-grid start (124.5 vs 128; 7 vs 7) in a quarter to half of its time; 2 is twice as
/// fast again but 9–14 % worse; 1 doubles the error.
pub(super) const COUNT_START_FACTOR: usize = 4;

/// The fewest triangles a count target's RTIN start has besides those the domain's shape
/// forces (or as many as the grid gives), however small the count. For small counts four
/// times is not enough where most of the grid is flat: a CT slice to 300 vertices kept
/// 310.5 from a start of 4 x, 196.5 from 100 k triangles and 194.4 from the full grid; Big
/// Tujunga and becmodel to 300 vertices and 1,000 triangles stay within 3 % of the full
/// grid's error either way (measured before the pre-sweep, which lowers them further).
pub(super) const COUNT_START_MIN_TRIANGLES: usize = 100_000;

/// The triangles a count target asks for (a mesh of `v` vertices has about `2 v`).
pub(super) fn target_triangles(options: &DecimationOptions) -> usize {
    let by_vertices = options
        .max_vertices
        .map_or(usize::MAX, |v| v.saturating_mul(2));
    options.max_triangles.unwrap_or(usize::MAX).min(by_vertices)
}
