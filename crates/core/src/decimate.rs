//! The decimation driver: the paper's sweep over candidate vertices (§3.1).

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use crate::hole::Retriangulator;
use crate::mesh::{Mesh, Star, VertexClass};
use crate::{DecimationOptions, Error, ErrorBound, Grid, Result, Tin, TinVertex};

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
    /// Vertices of the initial mesh (domain samples).
    pub initial_vertices: usize,
    /// Triangles of the initial mesh (two per valid cell).
    pub initial_triangles: usize,
    /// Vertices kept.
    pub final_vertices: usize,
    /// Triangles kept.
    pub final_triangles: usize,
    /// Largest error bound of any kept triangle: an upper bound on the true error.
    pub max_bound: f64,
    /// Sweeps over the candidate vertices until none could be removed.
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
/// The initial mesh splits every valid cell into two triangles; vertices are then removed
/// by the paper's algorithm: classify (§3.2), propagate error bounds (§3.3), retriangulate
/// the hole by ear selection (§3.4), in repeated sweeps in row-major order until a sweep
/// removes nothing. Corner vertices are never removed, so the domain is unchanged.
///
/// # Guarantee
/// Every triangle's [`ErrorBound`] bounds the error of every original sample it contains.
/// A removal is accepted only when all new bounds are at most
/// `max_error - max_error * 2^-40 - max|z| * 2^-40`, a slack that covers the rounding of
/// the bound arithmetic; so the true error, measured in `f64`, never exceeds `max_error`.
/// With `max_error` below that slack only vertices whose whole star is flat (every
/// neighbour has the same value) are removed, which is exact.
///
/// # Determinism
/// The result depends only on `grid` and `options`.
///
/// # Errors
/// [`Error::InvalidMaxError`] when `max_error` is negative, NaN or infinite.
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

/// [`decimate`], calling `progress` now and then (every 65,536 removal attempts and at
/// each sweep's start). The result is the same as [`decimate`]'s.
pub fn decimate_with_progress(
    grid: &Grid,
    options: &DecimationOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Decimation> {
    let max_error = options.max_error;
    if !(max_error.is_finite() && max_error >= 0.0) {
        return Err(Error::InvalidMaxError(max_error));
    }
    let started = Instant::now();
    let mut mesh = Mesh::from_grid(grid);
    let initial_triangles = mesh.triangle_count();
    let initial_vertices = (0..mesh.vertex_slots() as u32)
        .filter(|&v| mesh.contains_vertex(v))
        .count();
    let seconds_initial_mesh = started.elapsed().as_secs_f64();

    let slack = ROUNDING_SLACK * (max_error + grid.max_abs_value());
    let limit = if max_error > slack {
        max_error - slack
    } else {
        0.0
    };
    let started = Instant::now();
    let mut remover = Remover {
        star: Star::default(),
        hole: Retriangulator::default(),
        points: Vec::new(),
        bounds: Vec::new(),
        new_triangles: Vec::new(),
        selection: options.selection,
        limit,
    };

    // The paper's sweep, made cheap: a vertex whose star did not change since it last
    // failed would fail again, so each sweep visits only vertices whose star changed, in
    // the same row-major order a full sweep would.
    let n = mesh.vertex_slots();
    let mut queued = vec![false; n];
    let mut this_sweep: BinaryHeap<Reverse<u32>> = BinaryHeap::new();
    let mut next_sweep: Vec<u32> = Vec::new();
    for v in 0..n as u32 {
        if mesh.contains_vertex(v) {
            queued[v as usize] = true;
            next_sweep.push(v);
        }
    }
    let (mut sweeps, mut attempts, mut removed) = (0, 0, 0);
    while !next_sweep.is_empty() {
        sweeps += 1;
        this_sweep.extend(next_sweep.drain(..).map(Reverse));
        let mut sweep_size = this_sweep.len();
        let mut tried = 0usize;
        progress(Progress {
            sweep: sweeps,
            sweep_fraction: 0.0,
            removed,
        });
        while let Some(Reverse(v)) = this_sweep.pop() {
            queued[v as usize] = false;
            attempts += 1;
            tried += 1;
            if attempts % 65_536 == 0 {
                let sweep_fraction = tried as f64 / sweep_size.max(tried) as f64;
                progress(Progress {
                    sweep: sweeps,
                    sweep_fraction,
                    removed,
                });
            }
            if remover.try_remove(&mut mesh, v) {
                removed += 1;
                for &u in &remover.star.ring {
                    if !queued[u as usize] {
                        queued[u as usize] = true;
                        if u > v {
                            this_sweep.push(Reverse(u));
                            sweep_size += 1;
                        } else {
                            next_sweep.push(u);
                        }
                    }
                }
            }
        }
    }
    #[cfg(debug_assertions)]
    mesh.check_invariants();
    let seconds_decimation = started.elapsed().as_secs_f64();

    let (tin, max_bound) = extract(&mesh);
    let report = DecimationReport {
        initial_vertices,
        initial_triangles,
        final_vertices: tin.vertices.len(),
        final_triangles: tin.triangles.len(),
        max_bound,
        sweeps,
        attempts,
        seconds_initial_mesh,
        seconds_decimation,
    };
    Ok(Decimation { tin, report })
}

/// Removes single vertices; holds the buffers reused across attempts.
struct Remover {
    star: Star,
    hole: Retriangulator,
    points: Vec<crate::predicates::Point>,
    bounds: Vec<ErrorBound>,
    new_triangles: Vec<(u32, [u32; 3], ErrorBound)>,
    selection: crate::EdgeSelection,
    limit: f64,
}

impl Remover {
    /// Removes `v` if it is interior or boundary and its hole can be retriangulated within
    /// the limit; returns whether it did (then `self.star` holds its former star).
    fn try_remove(&mut self, mesh: &mut Mesh<'_>, v: u32) -> bool {
        if !mesh.contains_vertex(v) {
            return false;
        }
        mesh.star(v, &mut self.star);
        if mesh.classify(v, &self.star) == VertexClass::Corner {
            return false;
        }
        self.points.clear();
        self.points
            .extend(self.star.ring.iter().map(|&u| mesh.point(u)));
        let centre = mesh.point(v);
        if self.limit == 0.0 && self.points.iter().any(|p| p.z != centre.z) {
            // Below the rounding slack only exactly flat stars go: their bound arithmetic
            // is exact (all differences are zero).
            return false;
        }
        self.bounds.clear();
        self.bounds
            .extend(self.star.triangles.iter().map(|&t| mesh.bound(t)));
        self.hole.load(centre, &self.points, &self.bounds);
        let Some(triangles) = self.hole.retriangulate(self.selection, self.limit) else {
            return false;
        };
        self.new_triangles.clear();
        for (tri, &slot) in triangles.iter().zip(&self.star.triangles) {
            let corners = tri.corners.map(|i| self.star.ring[i as usize]);
            self.new_triangles.push((slot, corners, tri.bound));
        }
        mesh.replace_star(v, &self.star, &self.new_triangles);
        #[cfg(test)]
        mesh.check_invariants();
        true
    }
}

/// The mesh's live vertices (row-major) and triangles (slot order), and the largest bound.
fn extract(mesh: &Mesh<'_>) -> (Tin, f64) {
    let mut index = vec![u32::MAX; mesh.vertex_slots()];
    let mut vertices = Vec::new();
    for v in 0..mesh.vertex_slots() as u32 {
        if mesh.contains_vertex(v) {
            index[v as usize] = vertices.len() as u32;
            let p = mesh.point(v);
            vertices.push(TinVertex {
                x: p.x as u32,
                y: p.y as u32,
                z: p.z,
            });
        }
    }
    let mut triangles = Vec::with_capacity(mesh.triangle_count());
    let mut max_bound: f64 = 0.0;
    for (t, c) in mesh.live_triangles() {
        triangles.push(c.map(|v| index[v as usize]));
        max_bound = max_bound.max(mesh.bound(t).max());
    }
    (
        Tin {
            vertices,
            triangles,
        },
        max_bound,
    )
}
