//! Decimation of a triangulation of scattered points (the paper's general case: vertex
//! classes, holes and error bounds are defined on any 2D triangulation, §3), with the error
//! measured at every point.
//!
//! Every point starts as a vertex of the caller's triangulation (a Delaunay triangulation
//! of the points, say). A removed vertex is charged to the new triangle that contains it
//! (decided by the exact `i64` predicates); a removal is accepted only if every point
//! charged to the hole, the removed vertex included, is within the bound of the new
//! triangle containing it. Stars, classes, hole retriangulation (DP or ears) and both
//! error models are the grid's: only where samples are differs.
//!
//! Constrained edges (breaklines, outlines) stay in the TIN as chains of edges along them.
//! A vertex that ends a constrained edge, joins three or more, or bends a line is locked,
//! never removed, as is any vertex the caller locks (a line's own vertices, so that each
//! segment the caller was given stays a chain between its two ends). Any other vertex
//! between exactly two constrained edges on one straight line (a point lying on a
//! segment) is a boundary vertex of the line (the paper's rule, §3.2): its star is split along the
//! line into two half stars, each retriangulated as a boundary vertex's hole with the
//! straight edge joining the two line neighbours as its side, and that edge takes the
//! two constrained edges' place. A removal replaces only the triangles around the
//! removed vertex and keeps every edge of its ring, and scattered decimation makes no
//! edge flips, so no other constrained edge is ever touched.

use crate::coverage::HolePoints;
use crate::decimate::{effective_limit, MAX_ABS_HEIGHT};
use crate::hole::{Retriangulator, Rules};
use crate::mesh::{Mesh, Star, VertexClass, Vertices, NONE};
use crate::predicates::{in_closed_triangle, orient, Point};
use crate::{DecimationOptions, Error, ErrorBound, Result};

/// The largest lattice coordinate a [`Scatter`] takes: with coordinates in
/// `0..=MAX_SCATTER_COORDINATE` every difference is below 2^31, so each product in an
/// orientation determinant is below 2^62 and the determinant is exact in `i64`.
pub const MAX_SCATTER_COORDINATE: i64 = (1 << 31) - 1;

/// The largest hole (ring vertices) retriangulated, as on grids (see the grid driver).
const MAX_HOLE_RING: usize = 64;

/// Scattered samples at distinct integer lattice positions, each with a height.
///
/// Positions are in `0..=`[`MAX_SCATTER_COORDINATE`] on both axes, so the core's exact
/// predicates apply to them unchanged; heights are finite and within
/// [`MAX_ABS_HEIGHT`].
#[derive(Debug, Clone)]
pub struct Scatter {
    xy: Vec<[i64; 2]>,
    z: Vec<f64>,
}

impl Scatter {
    /// Scattered samples from lattice positions and heights (the same count).
    ///
    /// # Errors
    /// [`Error::Scatter`] when the counts differ, there are `u32::MAX` points or more, a
    /// position is outside `0..=MAX_SCATTER_COORDINATE` or a height is not finite;
    /// [`Error::HeightsTooLarge`] when some |height| exceeds [`MAX_ABS_HEIGHT`].
    pub fn new(xy: Vec<[i64; 2]>, z: Vec<f64>) -> Result<Scatter> {
        if xy.len() != z.len() {
            return Err(Error::Scatter(format!(
                "{} positions but {} heights",
                xy.len(),
                z.len()
            )));
        }
        if xy.len() >= u32::MAX as usize {
            return Err(Error::Scatter(format!(
                "{} points; at most {} fit 32-bit vertex ids",
                xy.len(),
                u32::MAX - 1
            )));
        }
        let range = 0..=MAX_SCATTER_COORDINATE;
        if let Some(p) = xy
            .iter()
            .find(|p| !range.contains(&p[0]) || !range.contains(&p[1]))
        {
            return Err(Error::Scatter(format!(
                "lattice position ({}, {}) is outside 0..={MAX_SCATTER_COORDINATE}",
                p[0], p[1]
            )));
        }
        if let Some(h) = z.iter().find(|h| !h.is_finite()) {
            return Err(Error::Scatter(format!("height {h} is not finite")));
        }
        let max_abs = z.iter().fold(0.0f64, |m, h| m.max(h.abs()));
        if max_abs > MAX_ABS_HEIGHT {
            return Err(Error::HeightsTooLarge(max_abs));
        }
        Ok(Scatter { xy, z })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.xy.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.xy.is_empty()
    }

    /// Lattice position of point `i`.
    ///
    /// # Panics
    /// When `i` is out of range.
    pub fn position(&self, i: usize) -> [i64; 2] {
        self.xy[i]
    }

    /// Height of point `i`.
    ///
    /// # Panics
    /// When `i` is out of range.
    pub fn height(&self, i: usize) -> f64 {
        self.z[i]
    }

    fn max_abs_height(&self) -> f64 {
        self.z.iter().fold(0.0f64, |m, h| m.max(h.abs()))
    }
}

impl Vertices for Scatter {
    #[inline]
    fn point(&self, v: u32) -> Point {
        let [x, y] = self.xy[v as usize];
        Point {
            x,
            y,
            z: self.z[v as usize],
        }
    }

    #[inline]
    fn sample_point(&self, v: u32) -> Point {
        self.point(v)
    }

    fn vertex_count(&self) -> usize {
        self.xy.len()
    }
}

/// A decimated triangulation of a [`Scatter`]: kept points and triangles over them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScatterTin {
    vertices: Vec<u32>,
    triangles: Vec<[u32; 3]>,
}

impl ScatterTin {
    /// The kept points, as indices into the [`Scatter`], increasing.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// Triangles as indices into [`ScatterTin::vertices`], counter-clockwise in lattice
    /// coordinates (x right, y up), non-degenerate; they tile the input triangulation's
    /// domain exactly.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}

/// What a scattered decimation reached.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScatterReport {
    /// Triangles of the input triangulation.
    pub initial_triangles: usize,
    /// Vertices kept.
    pub final_vertices: usize,
    /// Triangles kept.
    pub final_triangles: usize,
    /// Largest error bound of any kept triangle: an upper bound on the true error.
    pub max_bound: f64,
    /// Sweeps until nothing could be removed.
    pub sweeps: usize,
    /// Removal attempts.
    pub attempts: usize,
    /// Vertices locked by constrained edges (ends, junctions and bends of the lines) or
    /// by the caller: kept whatever the bound.
    pub locked_vertices: usize,
}

/// Decimates the triangulation `triangles` of `scatter` (counter-clockwise corner
/// triples of point indices forming a conforming triangulation, every point a vertex)
/// into a TIN within `options.max_error` of every point.
///
/// Vertices are removed in repeated sweeps in point order, each sweep visiting only the
/// vertices whose star changed (a vertex whose star did not change fails again), until a
/// sweep removes nothing (the paper's order, §3.1). Corner vertices (§3.2: any boundary
/// vertex whose two boundary edges are not collinear) are never removed, so the domain
/// (the triangulation's union, a convex hull for a Delaunay triangulation) is unchanged.
/// `options.error_model`, `retriangulation`, `selection` and `dp_max_ring` apply as on
/// grids; the start is always the given triangulation and the order the sweep.
///
/// # Guarantee
/// Every point is within `max_error` of the TIN's linear interpolation at its position,
/// with the same rounding slack as [`crate::decimate`] (`2^-40 (max_error + max|z|)`).
///
/// # Determinism
/// The result depends only on the inputs.
///
/// # Errors
/// [`Error::InvalidMaxError`] for a negative, NaN or infinite bound; [`Error::Scatter`]
/// for a count or vertical target (not supported here), a triangle that is not
/// counter-clockwise or names a missing point, or a point in no triangle.
pub fn decimate_scatter(
    scatter: &Scatter,
    triangles: Vec<[u32; 3]>,
    options: &DecimationOptions,
) -> Result<(ScatterTin, ScatterReport)> {
    decimate_scatter_constrained(scatter, triangles, &[], &[], options)
}

/// [`decimate_scatter`] keeping the `constrained` edges (pairs of point indices, each an
/// edge of `triangles`, in either direction): each one is covered by a chain of the
/// result's edges along it (see the module documentation). The `locked` points are kept
/// whatever the bound.
///
/// # Guarantee
/// As [`decimate_scatter`], and every constrained edge lies on edges of the TIN: either
/// it is one, or the vertices between its ends were removed as boundary vertices of a
/// straight line and one straight TIN edge along the line covers it. The ends, junctions
/// and bends of the lines, and the `locked` points, are vertices of the TIN.
///
/// # Errors
/// As [`decimate_scatter`], and [`Error::Scatter`] for a constrained edge that is not an
/// edge of `triangles`.
pub fn decimate_scatter_constrained(
    scatter: &Scatter,
    triangles: Vec<[u32; 3]>,
    constrained: &[[u32; 2]],
    locked: &[u32],
    options: &DecimationOptions,
) -> Result<(ScatterTin, ScatterReport)> {
    let max_error = options.max_error;
    if !max_error.is_finite() || max_error < 0.0 {
        return Err(Error::InvalidMaxError(max_error));
    }
    if options.max_triangles.is_some() || options.max_vertices.is_some() {
        return Err(Error::Scatter(
            "triangle or vertex count targets are not supported for points".into(),
        ));
    }
    let n = scatter.len();
    let mut used = vec![false; n];
    for c in &triangles {
        if c.iter().any(|&v| v as usize >= n) {
            return Err(Error::Scatter(format!(
                "triangle {c:?} names a missing point"
            )));
        }
        let [a, b, cc] = c.map(|v| scatter.point(v));
        if orient(&a, &b, &cc) <= 0 {
            return Err(Error::Scatter(format!(
                "triangle {c:?} is not counter-clockwise"
            )));
        }
        for &v in c {
            used[v as usize] = true;
        }
    }
    if let Some(v) = used.iter().position(|u| !u) {
        return Err(Error::Scatter(format!(
            "point {v} is not a vertex of the triangulation"
        )));
    }
    drop(used);
    let mut lines = line_roles(scatter, n, &triangles, constrained)?;
    for &v in locked {
        let role = lines.get_mut(v as usize).ok_or_else(|| {
            Error::Scatter(format!("locked point {v} is not a point of the scatter"))
        })?;
        *role = Line::Locked;
    }
    let locked_count = lines.iter().filter(|&&l| l == Line::Locked).count();
    let initial_triangles = triangles.len();
    let limit = effective_limit(max_error, scatter.max_abs_height());
    let mut mesh = Mesh::from_conforming(scatter, triangles);
    #[cfg(any(test, debug_assertions))]
    mesh.check_invariants();
    let rules = Rules {
        grid: &HolePoints::default(),
        model: options.error_model,
        selection: options.selection,
        method: options.retriangulation,
        dp_max_ring: options.dp_max_ring,
        limit,
        edge_limit: &crate::edge_limit::NO_EDGE_LIMIT,
        levels: None,
    };
    let mut remover = ScatterRemover::new(&mesh, rules, lines);
    let (sweeps, attempts) = match options.order {
        crate::Order::Sweep => remover.sweep(&mut mesh),
        crate::Order::Greedy => remover.greedy(&mut mesh),
    };
    #[cfg(any(test, debug_assertions))]
    mesh.check_invariants();
    let max_bound = mesh
        .live_triangles()
        .fold(0.0f64, |m, (t, _)| m.max(mesh.bound(t).max()))
        .min(limit);
    let (vertices, triangles) = mesh.into_numbered();
    let report = ScatterReport {
        initial_triangles,
        final_vertices: vertices.len(),
        final_triangles: triangles.len(),
        max_bound,
        sweeps,
        attempts,
        locked_vertices: locked_count,
    };
    Ok((
        ScatterTin {
            vertices,
            triangles,
        },
        report,
    ))
}

/// What the constrained edges make of a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Line {
    /// On no constrained edge.
    Free,
    /// Between exactly two constrained edges, to these two points, on the straight
    /// segment joining them: removable as a boundary vertex of the line.
    Through(u32, u32),
    /// Ends a constrained edge, joins three or more, or bends a line: kept.
    Locked,
}

/// Each point's [`Line`] role; every constrained edge must be an edge of `triangles`.
fn line_roles(
    scatter: &Scatter,
    n: usize,
    triangles: &[[u32; 3]],
    constrained: &[[u32; 2]],
) -> Result<Vec<Line>> {
    let mut roles = vec![Line::Free; n];
    if constrained.is_empty() {
        return Ok(roles);
    }
    let key = |a: u32, b: u32| (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
    let mut edges: Vec<u64> = triangles
        .iter()
        .flat_map(|c| [key(c[0], c[1]), key(c[1], c[2]), key(c[2], c[0])])
        .collect();
    edges.sort_unstable();
    let mut wanted: Vec<u64> = Vec::with_capacity(constrained.len());
    for &[a, b] in constrained {
        if a == b || edges.binary_search(&key(a, b)).is_err() {
            return Err(Error::Scatter(format!(
                "constrained edge {a}-{b} is not an edge of the triangulation"
            )));
        }
        wanted.push(key(a, b));
    }
    wanted.sort_unstable();
    wanted.dedup();
    // Each point's constrained neighbours, up to three (three means a junction).
    let mut ends: Vec<Vec<u32>> = vec![Vec::new(); n];
    for k in wanted {
        let (a, b) = ((k >> 32) as u32, k as u32);
        for (p, q) in [(a, b), (b, a)] {
            if ends[p as usize].len() < 3 {
                ends[p as usize].push(q);
            }
        }
    }
    for (v, near) in ends.iter().enumerate() {
        roles[v] = match near[..] {
            [] => Line::Free,
            [a, b] if straight_between(scatter, a, v as u32, b) => Line::Through(a, b),
            _ => Line::Locked,
        };
    }
    Ok(roles)
}

/// Whether `v` lies strictly between `a` and `b` on the segment joining them (exact).
fn straight_between(scatter: &Scatter, a: u32, v: u32, b: u32) -> bool {
    let (a, c, b) = (scatter.point(a), scatter.point(v), scatter.point(b));
    orient(&a, &c, &b) == 0 && (a.x - c.x) * (b.x - c.x) + (a.y - c.y) * (b.y - c.y) < 0
}

/// Removes vertices and keeps each removed point charged to the triangle containing it:
/// per triangle slot the first charged point, per point the next one in its triangle.
struct ScatterRemover {
    first: Vec<u32>,
    next: Vec<u32>,
    star: Star,
    hole: Retriangulator,
    hole_points: HolePoints,
    /// Point ids of `hole_points.points`, in the same order.
    hole_ids: Vec<u32>,
    /// The points of every hole of the last plan (two for a split star) and their ids:
    /// what [`ScatterRemover::apply`] charges to the new triangles.
    charged_points: Vec<Point>,
    charged_ids: Vec<u32>,
    /// A half star's ring and triangles (a split star's).
    half_ring: Vec<u32>,
    half_triangles: Vec<u32>,
    ring: Vec<Point>,
    bounds: Vec<ErrorBound>,
    new_triangles: Vec<(u32, [u32; 3], ErrorBound)>,
    /// The new triangles' slots, corner points and bounding boxes (`[x_lo, x_hi, y_lo,
    /// y_hi]`), while charging points to them.
    corner_points: Vec<(u32, [Point; 3], [i64; 4])>,
    model: crate::ErrorModel,
    selection: crate::EdgeSelection,
    method: crate::Retriangulation,
    dp_max_ring: usize,
    limit: f64,
    /// Each point's role on the constrained edges, kept current as line vertices go.
    lines: Vec<Line>,
}

impl ScatterRemover {
    fn new(
        mesh: &Mesh<'_, Scatter>,
        rules: Rules<'_, HolePoints>,
        lines: Vec<Line>,
    ) -> ScatterRemover {
        ScatterRemover {
            first: vec![NONE; mesh.triangle_slots()],
            next: vec![NONE; mesh.vertex_slots()],
            star: Star::default(),
            hole: Retriangulator::default(),
            hole_points: HolePoints::default(),
            hole_ids: Vec::new(),
            charged_points: Vec::new(),
            charged_ids: Vec::new(),
            half_ring: Vec::new(),
            half_triangles: Vec::new(),
            ring: Vec::new(),
            bounds: Vec::new(),
            new_triangles: Vec::new(),
            corner_points: Vec::new(),
            model: rules.model,
            selection: rules.selection,
            method: rules.method,
            dp_max_ring: rules.dp_max_ring,
            limit: rules.limit,
            lines,
        }
    }

    /// Sweeps until one removes nothing; returns the sweeps and the attempts.
    fn sweep(&mut self, mesh: &mut Mesh<'_, Scatter>) -> (usize, usize) {
        let n = mesh.vertex_slots();
        let mut queued = vec![true; n];
        let mut candidates: Vec<u32> = (0..n as u32).collect();
        let (mut sweeps, mut attempts) = (0, 0);
        let mut changed: Vec<u32> = Vec::new();
        while !candidates.is_empty() {
            sweeps += 1;
            for &v in &candidates {
                queued[v as usize] = false;
            }
            for &v in &candidates {
                if !mesh.contains_vertex(v) {
                    continue;
                }
                attempts += 1;
                if self.plan(mesh, v).is_some() {
                    self.apply(mesh, v);
                    for &u in &self.star.ring {
                        if !queued[u as usize] {
                            queued[u as usize] = true;
                            changed.push(u);
                        }
                    }
                }
            }
            // Next sweep: the vertices whose star changed, in point order.
            changed.sort_unstable();
            std::mem::swap(&mut candidates, &mut changed);
            changed.clear();
        }
        (sweeps, attempts)
    }

    /// The greedy order: always removes the vertex whose best retriangulation has the
    /// smallest largest bound (ties to the lower point index), re-planning a vertex's
    /// neighbours after each removal; returns 1 (one pass) and the attempts. The result
    /// depends on the points and options alone.
    fn greedy(&mut self, mesh: &mut Mesh<'_, Scatter>) -> (usize, usize) {
        use crate::decimate::order::Candidate;
        let n = mesh.vertex_slots();
        let mut version = vec![0u32; n];
        let mut heap = std::collections::BinaryHeap::new();
        let mut attempts = 0;
        for v in 0..n as u32 {
            if mesh.contains_vertex(v) {
                attempts += 1;
                if let Some(cost) = self.plan(mesh, v) {
                    heap.push(Candidate {
                        cost,
                        vertex: v,
                        version: 0,
                    });
                }
            }
        }
        let mut ring = Vec::new();
        while let Some(c) = heap.pop() {
            let v = c.vertex;
            if c.version != version[v as usize] || !mesh.contains_vertex(v) {
                continue;
            }
            attempts += 1;
            // The plan is redone: other plans since have used the remover's buffers.
            let Some(cost) = self.plan(mesh, v) else {
                continue;
            };
            debug_assert_eq!(cost.to_bits(), c.cost.to_bits(), "a current key is exact");
            self.apply(mesh, v);
            ring.clear();
            ring.extend_from_slice(&self.star.ring);
            for &u in &ring {
                version[u as usize] = version[u as usize].wrapping_add(1);
                if !mesh.contains_vertex(u) {
                    continue;
                }
                attempts += 1;
                if let Some(cost) = self.plan(mesh, u) {
                    heap.push(Candidate {
                        cost,
                        vertex: u,
                        version: version[u as usize],
                    });
                }
            }
        }
        (1, attempts)
    }

    /// Plans the removal of `v`: `Some(largest new bound)` when it is interior or boundary
    /// (of the domain, or of a straight constrained line) and its hole (each half of its
    /// star, for a line vertex) has a triangulation within the limit at every point
    /// charged to it.
    fn plan(&mut self, mesh: &Mesh<'_, Scatter>, v: u32) -> Option<f64> {
        let line = self.lines[v as usize];
        if line == Line::Locked {
            return None;
        }
        mesh.star(v, &mut self.star);
        if self.star.ring.len() > MAX_HOLE_RING {
            return None;
        }
        self.new_triangles.clear();
        self.charged_points.clear();
        self.charged_ids.clear();
        let star = std::mem::take(&mut self.star);
        let planned = match line {
            Line::Through(a, b) if !star.open => {
                // Split along the line: from `a` round to `b`, then from `b` round to `a`.
                let m = star.ring.len();
                let at = |u: u32| star.ring.iter().position(|&r| r == u);
                let (Some(ia), Some(ib)) = (at(a), at(b)) else {
                    debug_assert!(false, "a line neighbour is in the star");
                    self.star = star;
                    return None;
                };
                let mut worst = 0.0f64;
                let mut ok = true;
                for (from, to) in [(ia, ib), (ib, ia)] {
                    let k = (to + m - from) % m;
                    self.half_ring.clear();
                    self.half_triangles.clear();
                    self.half_ring
                        .extend((0..=k).map(|i| star.ring[(from + i) % m]));
                    self.half_triangles
                        .extend((0..k).map(|i| star.triangles[(from + i) % m]));
                    let (ring, triangles) = (
                        std::mem::take(&mut self.half_ring),
                        std::mem::take(&mut self.half_triangles),
                    );
                    let half = self.plan_hole(mesh, v, &ring, &triangles);
                    (self.half_ring, self.half_triangles) = (ring, triangles);
                    match half {
                        Some(w) => worst = worst.max(w),
                        None => {
                            ok = false;
                            break;
                        }
                    }
                }
                ok.then_some(worst)
            }
            Line::Through(a, b) => {
                // On the domain's boundary: only where the line is the boundary there.
                let ends = (
                    star.ring[0],
                    *star.ring.last().expect("a star has neighbours"),
                );
                if (ends == (a, b) || ends == (b, a))
                    && mesh.classify(v, &star) == VertexClass::Boundary
                {
                    self.plan_hole(mesh, v, &star.ring, &star.triangles)
                } else {
                    None
                }
            }
            _ if mesh.classify(v, &star) == VertexClass::Corner => None,
            _ => self.plan_hole(mesh, v, &star.ring, &star.triangles),
        };
        self.star = star;
        planned
    }

    /// Plans one hole of the removal of `v`: the fan of its star `triangles` between the
    /// neighbours `ring` (counter-clockwise; a closed fan has as many triangles as ring
    /// vertices, an open one one fewer). Adds the new triangles (in the old triangles'
    /// slots) to `new_triangles` and the hole's points to the charged ones; returns the
    /// largest new bound, or `None` when no triangulation is within the limit.
    fn plan_hole(
        &mut self,
        mesh: &Mesh<'_, Scatter>,
        v: u32,
        ring: &[u32],
        triangles: &[u32],
    ) -> Option<f64> {
        self.ring.clear();
        self.ring.extend(ring.iter().map(|&u| mesh.point(u)));
        let centre = mesh.sample_point(v);
        if self.limit == 0.0 && self.ring.iter().any(|p| p.z != centre.z) {
            // Below the rounding slack only exactly flat stars go, as on grids.
            return None;
        }
        let (lo, hi) = self
            .ring
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.z), hi.max(p.z))
            });
        if centre.z - hi > self.limit || lo - centre.z > self.limit {
            return None;
        }
        self.hole_points.points.clear();
        self.hole_ids.clear();
        self.hole_points.points.push(centre);
        self.hole_ids.push(v);
        for &t in triangles {
            let mut p = self.first[t as usize];
            while p != NONE {
                self.hole_points.points.push(mesh.sample_point(p));
                self.hole_ids.push(p);
                p = self.next[p as usize];
            }
        }
        self.bounds.clear();
        self.bounds.extend(triangles.iter().map(|&t| mesh.bound(t)));
        self.hole.load(centre, &self.ring, &self.bounds);
        let rules = Rules {
            grid: &self.hole_points,
            model: self.model,
            selection: self.selection,
            method: self.method,
            dp_max_ring: self.dp_max_ring,
            limit: self.limit,
            edge_limit: &crate::edge_limit::NO_EDGE_LIMIT,
            levels: None,
        };
        let (new, worst) = self.hole.retriangulate(&rules)?;
        for (tri, &slot) in new.iter().zip(triangles) {
            let corners = tri.corners.map(|i| ring[i as usize]);
            self.new_triangles.push((slot, corners, tri.bound));
        }
        // The removed vertex is in both halves of a split star: charged once.
        let skip = usize::from(!self.charged_ids.is_empty());
        self.charged_points
            .extend_from_slice(&self.hole_points.points[skip..]);
        self.charged_ids.extend_from_slice(&self.hole_ids[skip..]);
        Some(worst)
    }

    /// Carries out the last successful plan (for `v`, mesh unchanged since) and charges
    /// the hole's points to the new triangles containing them (the first in hole order
    /// for a point on a shared edge: both measured it).
    fn apply(&mut self, mesh: &mut Mesh<'_, Scatter>, v: u32) {
        mesh.replace_star(v, &self.star, &self.new_triangles);
        for &t in &self.star.triangles {
            self.first[t as usize] = NONE;
        }
        self.corner_points.clear();
        self.corner_points
            .extend(self.new_triangles.iter().map(|(slot, c, _)| {
                let [a, b, c] = c.map(|u| mesh.point(u));
                let x = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
                let y = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
                (*slot, [a, b, c], [x.0, x.1, y.0, y.1])
            }));
        for (&p, point) in self.charged_ids.iter().zip(&self.charged_points) {
            let home = self
                .corner_points
                .iter()
                .find(|(_, [a, b, c], [x0, x1, y0, y1])| {
                    (*x0..=*x1).contains(&point.x)
                        && (*y0..=*y1).contains(&point.y)
                        && in_closed_triangle(a, b, c, point)
                });
            // Some new triangle holds every point of the hole: they tile it.
            let slot = home.map_or(self.new_triangles[0].0, |h| h.0);
            debug_assert!(home.is_some(), "point {p} outside its hole");
            self.next[p as usize] = self.first[slot as usize];
            self.first[slot as usize] = p;
        }
        // The straight edge between a line vertex's neighbours takes the place of its two
        // constrained edges.
        if let Line::Through(a, b) = self.lines[v as usize] {
            for (end, other) in [(a, b), (b, a)] {
                if let Line::Through(x, y) = self.lines[end as usize] {
                    let swap = |u: u32| if u == v { other } else { u };
                    self.lines[end as usize] = Line::Through(swap(x), swap(y));
                }
            }
            self.lines[v as usize] = Line::Free;
        }
        #[cfg(test)]
        mesh.check_invariants();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ErrorModel, Retriangulation};

    /// Points on a sheared lattice (odd columns raised by one), each quad split in two:
    /// a conforming triangulation that is not a grid's.
    fn lattice_scatter(w: i64, h: i64, f: impl Fn(f64, f64) -> f64) -> (Scatter, Vec<[u32; 3]>) {
        let mut xy = Vec::new();
        let mut z = Vec::new();
        for y in 0..h {
            for x in 0..w {
                xy.push([x * 3, y * 2 + (x % 2)]);
                z.push(f(x as f64, y as f64));
            }
        }
        let mut tris = Vec::new();
        for y in 0..h - 1 {
            for x in 0..w - 1 {
                let a = (y * w + x) as u32;
                let (b, c, d) = (a + 1, a + 1 + w as u32, a + w as u32);
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        (Scatter::new(xy, z).unwrap(), tris)
    }

    /// Measures every point against the TIN by brute force (closed triangles, f64).
    fn worst_error(s: &Scatter, tin: &ScatterTin) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..s.len() {
            let p = s.point(i as u32);
            let mut best = f64::INFINITY;
            for t in tin.triangles() {
                let [a, b, c] = t.map(|k| s.point(tin.vertices()[k as usize]));
                if in_closed_triangle(&a, &b, &c, &p) {
                    let d = orient(&a, &b, &c) as f64;
                    let (wa, wb) = (orient(&b, &c, &p) as f64 / d, orient(&c, &a, &p) as f64 / d);
                    let z = wa * a.z + wb * b.z + (1.0 - wa - wb) * c.z;
                    best = best.min((z - p.z).abs());
                }
            }
            assert!(best.is_finite(), "point {i} in no triangle");
            worst = worst.max(best);
        }
        worst
    }

    #[test]
    fn a_plane_keeps_only_its_hull_corners() {
        let (s, tris) = lattice_scatter(12, 9, |x, y| 2.0 * x - y);
        let (tin, report) = decimate_scatter(&s, tris, &DecimationOptions::new(1e-6)).unwrap();
        // The plane z = 2x - y is not linear in the lattice positions (y is shifted on odd
        // columns), so interior vertices may stay; the bound must hold regardless.
        assert!(worst_error(&s, &tin) <= 1e-6);
        assert!(report.final_vertices < s.len());
    }

    #[test]
    fn every_point_within_the_bound_for_both_models_and_methods() {
        let (s, tris) = lattice_scatter(20, 15, |x, y| {
            (x * 0.7).sin() * 10.0 + (y * 0.4).cos() * 6.0
        });
        for model in [ErrorModel::Exact, ErrorModel::Bounds] {
            for method in [Retriangulation::Dp, Retriangulation::Ears] {
                let mut options = DecimationOptions::new(1.5);
                options.error_model = model;
                options.retriangulation = method;
                let (tin, report) = decimate_scatter(&s, tris.clone(), &options).unwrap();
                let worst = worst_error(&s, &tin);
                assert!(worst <= 1.5, "{model:?} {method:?}: {worst}");
                assert!(report.final_vertices < s.len() / 2, "{model:?} {method:?}");
                assert!(report.max_bound <= 1.5);
            }
        }
    }

    /// Random distinct lattice points, the four corners of the square among them, with
    /// heights from `f`, and their Delaunay triangulation (spade).
    fn random_scatter(
        n: usize,
        seed: u64,
        side: i64,
        f: &dyn Fn(f64, f64) -> f64,
    ) -> (Scatter, Vec<[u32; 3]>) {
        use spade::{DelaunayTriangulation, Point2, Triangulation};
        let mut s = seed;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut seen = std::collections::BTreeSet::new();
        let mut xy = vec![[0, 0], [side, 0], [0, side], [side, side]];
        seen.extend(xy.iter().copied());
        while xy.len() < n {
            let p = [
                (next() % (side as u64 + 1)) as i64,
                (next() % (side as u64 + 1)) as i64,
            ];
            if seen.insert(p) {
                xy.push(p);
            }
        }
        let z = xy.iter().map(|p| f(p[0] as f64, p[1] as f64)).collect();
        let d: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::bulk_load(
            xy.iter()
                .map(|p| Point2::new(p[0] as f64, p[1] as f64))
                .collect(),
        )
        .unwrap();
        // Bulk loading reorders the vertices: back to point indices by position.
        let index: std::collections::BTreeMap<[i64; 2], u32> =
            xy.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect();
        let tris = d
            .inner_faces()
            .map(|f| {
                f.vertices().map(|v| {
                    let p = v.position();
                    index[&[p.x as i64, p.y as i64]]
                })
            })
            .collect();
        (Scatter::new(xy, z).unwrap(), tris)
    }

    #[test]
    fn random_points_within_the_bound_for_every_model_method_and_seed() {
        for seed in [1, 2, 3] {
            let (s, tris) = random_scatter(400, seed, 1000, &|x, y| {
                (x / 90.0).sin() * 30.0 + (y / 140.0).cos() * 20.0 + ((x * y) % 7.0) * 0.1
            });
            for model in [ErrorModel::Exact, ErrorModel::Bounds] {
                for (method, order) in [
                    (Retriangulation::Dp, crate::Order::Sweep),
                    (Retriangulation::Ears, crate::Order::Sweep),
                    (Retriangulation::Dp, crate::Order::Greedy),
                ] {
                    for bound in [0.5, 4.0] {
                        let mut options = DecimationOptions::new(bound).with_order(order);
                        options.error_model = model;
                        options.retriangulation = method;
                        let (tin, report) = decimate_scatter(&s, tris.clone(), &options).unwrap();
                        let worst = worst_error(&s, &tin);
                        assert!(
                            worst <= bound,
                            "{seed} {model:?} {method:?} {order:?} {bound}: {worst}"
                        );
                        assert!(
                            report.final_vertices < s.len(),
                            "{seed} {model:?} {method:?} {order:?}"
                        );
                        // The hull's corners stay.
                        for corner in 0..4u32 {
                            assert!(tin.vertices().contains(&corner));
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_plane_of_random_points_keeps_only_its_corners() {
        let (s, tris) = random_scatter(300, 9, 500, &|x, y| 3.0 + 0.5 * x - 0.25 * y);
        let (tin, _) = decimate_scatter(&s, tris, &DecimationOptions::new(1e-6)).unwrap();
        assert_eq!(tin.vertices(), &[0, 1, 2, 3]);
        assert_eq!(tin.triangles().len(), 2);
    }

    /// `random_scatter`'s points re-triangulated by spade's constrained Delaunay with two
    /// polylines through some of the points (a zigzag and a closed ring, not crossing), and
    /// the constrained edges as point pairs.
    fn constrained_scatter(
        seed: u64,
        f: impl Fn(f64, f64) -> f64,
    ) -> (Scatter, Vec<[u32; 3]>, Vec<[u32; 2]>) {
        use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
        let (s, _) = random_scatter(400, seed, 1000, &f);
        let mut xy: Vec<[i64; 2]> = (0..s.len()).map(|i| s.position(i)).collect();
        let mut z: Vec<f64> = (0..s.len()).map(|i| s.height(i)).collect();
        let zigzag: Vec<[i64; 2]> = (0..=10)
            .map(|k| [100 + 80 * k, 300 + 60 * (k % 2)])
            .collect();
        let ring = vec![[300, 600], [700, 620], [650, 900], [320, 880], [300, 600]];
        let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
            ConstrainedDelaunayTriangulation::bulk_load(
                xy.iter()
                    .map(|p| Point2::new(p[0] as f64, p[1] as f64))
                    .collect(),
            )
            .unwrap();
        for line in [&zigzag, &ring] {
            let handles: Vec<_> = line
                .iter()
                .map(|p| cdt.insert(Point2::new(p[0] as f64, p[1] as f64)).unwrap())
                .collect();
            for w in handles.windows(2) {
                assert!(cdt.add_constraint(w[0], w[1]));
            }
        }
        let mut index: std::collections::BTreeMap<[i64; 2], u32> =
            xy.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect();
        for v in cdt.vertices() {
            let p = v.position();
            let p = [p.x as i64, p.y as i64];
            if let std::collections::btree_map::Entry::Vacant(e) = index.entry(p) {
                e.insert(xy.len() as u32);
                xy.push(p);
                z.push(f(p[0] as f64, p[1] as f64));
            }
        }
        let id = |v: spade::handles::VertexHandle<Point2<f64>, (), spade::CdtEdge<()>, ()>| {
            let p = v.position();
            index[&[p.x as i64, p.y as i64]]
        };
        let tris = cdt.inner_faces().map(|f| f.vertices().map(id)).collect();
        let edges: Vec<[u32; 2]> = cdt
            .undirected_edges()
            .filter(|e| e.is_constraint_edge())
            .map(|e| e.vertices().map(id))
            .collect();
        assert!(edges.len() >= 14);
        (Scatter::new(xy, z).unwrap(), tris, edges)
    }

    fn has_edge(tin: &ScatterTin, [a, b]: [u32; 2]) -> bool {
        let local = |p: u32| tin.vertices().binary_search(&p).ok().map(|i| i as u32);
        let (Some(a), Some(b)) = (local(a), local(b)) else {
            return false;
        };
        tin.triangles().iter().any(|t| {
            (0..3).any(|e| (t[e] == a && t[(e + 1) % 3] == b) || (t[e] == b && t[(e + 1) % 3] == a))
        })
    }

    #[test]
    fn constrained_edges_are_kept_under_every_option() {
        use crate::{EdgeSelection, VertexHeights};
        for seed in [4, 5] {
            let f = |x: f64, y: f64| (x / 90.0).sin() * 30.0 + (y / 140.0).cos() * 20.0;
            let (s, tris, edges) = constrained_scatter(seed, f);
            let mut all = Vec::new();
            for model in [ErrorModel::Bounds, ErrorModel::Exact] {
                for selection in [
                    EdgeSelection::Hybrid,
                    EdgeSelection::MinError,
                    EdgeSelection::MinIntroduced,
                ] {
                    for method in [Retriangulation::Ears, Retriangulation::Dp] {
                        let base = DecimationOptions::paper(2.0)
                            .with_error_model(model)
                            .with_selection(selection)
                            .with_retriangulation(method);
                        all.push(base.clone());
                        all.push(base.clone().with_flip_rounds(2));
                        all.push(base.clone().with_extend_rounds(2));
                        all.push(base.with_vertex_heights(VertexHeights::Samples));
                    }
                }
            }
            for options in all {
                let (tin, report) =
                    decimate_scatter_constrained(&s, tris.clone(), &edges, &[], &options).unwrap();
                for &e in &edges {
                    assert!(has_edge(&tin, e), "{seed} {options:?}: edge {e:?} lost");
                }
                assert!(worst_error(&s, &tin) <= 2.0, "{seed} {options:?}");
                assert!(report.final_vertices < s.len() - 100, "{seed} {options:?}");
                assert!(report.locked_vertices >= 15);
            }
            // Without the constraints the same run loses some of those edges: the check
            // above can fail.
            let (tin, _) = decimate_scatter(&s, tris, &DecimationOptions::paper(2.0)).unwrap();
            assert!(edges.iter().any(|&e| !has_edge(&tin, e)));
        }
    }

    #[test]
    fn a_straight_line_loses_its_inner_vertices_and_keeps_its_ends_and_bends() {
        use crate::EdgeSelection;
        // A crease along the lattice column x = 10 (straight: positions (3x, 2y + x % 2)),
        // constrained from y = 2 to 18; and a bent line up column 4 then across to 5.
        let (s, tris) = lattice_scatter(21, 21, |x, _| 2.0 * (x - 10.0).abs());
        let id = |x: u32, y: u32| y * 21 + x;
        let mut edges: Vec<[u32; 2]> = (2..18).map(|y| [id(10, y), id(10, y + 1)]).collect();
        edges.extend([
            [id(4, 3), id(4, 4)],
            [id(4, 4), id(4, 5)],
            [id(4, 5), id(5, 5)],
        ]);
        for model in [ErrorModel::Bounds, ErrorModel::Exact] {
            for method in [Retriangulation::Ears, Retriangulation::Dp] {
                for order in [crate::Order::Sweep, crate::Order::Greedy] {
                    let options = DecimationOptions::new(0.01)
                        .with_error_model(model)
                        .with_retriangulation(method)
                        .with_selection(EdgeSelection::Hybrid)
                        .with_order(order);
                    let (tin, report) =
                        decimate_scatter_constrained(&s, tris.clone(), &edges, &[], &options)
                            .unwrap();
                    let what = format!("{model:?} {method:?} {order:?}");
                    assert!(worst_error(&s, &tin) <= 0.01, "{what}");
                    let kept = |p: u32| tin.vertices().binary_search(&p).is_ok();
                    // Ends and the bend are locked; every vertex between the ends went, and
                    // one straight edge along the line covers the constrained ones.
                    for p in [id(10, 2), id(10, 18), id(4, 3), id(4, 5), id(5, 5)] {
                        assert!(kept(p), "{what}: line vertex {p} removed");
                    }
                    assert_eq!(report.locked_vertices, 5, "{what}");
                    assert!((3..18).all(|y| !kept(id(10, y))), "{what}");
                    assert!(!kept(id(4, 4)), "{what}");
                    assert!(has_edge(&tin, [id(10, 2), id(10, 18)]), "{what}");
                    assert!(has_edge(&tin, [id(4, 3), id(4, 5)]), "{what}");
                    assert!(has_edge(&tin, [id(4, 5), id(5, 5)]), "{what}");
                }
            }
        }
        // A vertex the caller locks (a line's own vertex) stays, and splits the edge.
        let options = DecimationOptions::new(0.01);
        let (tin, report) =
            decimate_scatter_constrained(&s, tris.clone(), &edges, &[id(10, 9)], &options).unwrap();
        assert_eq!(report.locked_vertices, 6);
        assert!(has_edge(&tin, [id(10, 2), id(10, 9)]) && has_edge(&tin, [id(10, 9), id(10, 18)]));
        let outside = decimate_scatter_constrained(&s, tris, &edges, &[21 * 21], &options);
        assert!(outside.is_err());
    }

    #[test]
    fn a_plane_keeps_its_corners_and_its_constrained_vertices_only() {
        let (s, tris, edges) = constrained_scatter(6, |x, y| 3.0 + 0.5 * x - 0.25 * y);
        let (tin, _) =
            decimate_scatter_constrained(&s, tris, &edges, &[], &DecimationOptions::new(1e-6))
                .unwrap();
        let mut want: Vec<u32> = edges.iter().flatten().copied().chain(0..4).collect();
        want.sort_unstable();
        want.dedup();
        assert_eq!(tin.vertices(), &want[..]);
        for &e in &edges {
            assert!(has_edge(&tin, e));
        }
    }

    #[test]
    fn a_constrained_edge_not_in_the_triangulation_is_refused() {
        let (s, tris) = lattice_scatter(3, 3, |_, _| 0.0);
        // Points 0 and 8 are opposite corners: never an edge of the lattice's triangles.
        let e =
            decimate_scatter_constrained(&s, tris, &[[0, 8]], &[], &DecimationOptions::new(1.0));
        assert!(matches!(e, Err(Error::Scatter(m)) if m.contains("0-8")));
    }

    #[test]
    fn bad_triangulations_are_refused() {
        let (s, mut tris) = lattice_scatter(3, 3, |_, _| 0.0);
        tris[0].swap(1, 2);
        assert!(matches!(
            decimate_scatter(&s, tris, &DecimationOptions::new(1.0)),
            Err(Error::Scatter(_))
        ));
        let (s, mut tris) = lattice_scatter(3, 3, |_, _| 0.0);
        tris.truncate(2);
        assert!(decimate_scatter(&s, tris, &DecimationOptions::new(1.0)).is_err());
        assert!(Scatter::new(vec![[0, -1]], vec![0.0]).is_err());
        assert!(Scatter::new(vec![[0, 0]], vec![f64::NAN]).is_err());
    }

    #[test]
    fn same_input_same_output() {
        let (s, tris) = lattice_scatter(15, 11, |x, y| (x * y).sqrt());
        for o in [
            DecimationOptions::new(0.3),
            DecimationOptions::new(0.3).with_order(crate::Order::Greedy),
        ] {
            let a = decimate_scatter(&s, tris.clone(), &o).unwrap();
            let b = decimate_scatter(&s, tris.clone(), &o).unwrap();
            assert_eq!(a, b);
        }
    }

    /// The greedy order removes the cheapest vertex first: on the same points it keeps a
    /// different mesh than the sweep, within the same bound, and never a larger one by
    /// more than a few vertices (measured: usually smaller).
    #[test]
    fn the_greedy_order_is_honoured() {
        let (s, tris) = random_scatter(600, 4, 1000, &|x, y| {
            (x / 70.0).sin() * 25.0 + (y / 110.0).cos() * 15.0
        });
        let sweep = DecimationOptions::new(1.0);
        let greedy = DecimationOptions::new(1.0).with_order(crate::Order::Greedy);
        let (a, _) = decimate_scatter(&s, tris.clone(), &sweep).unwrap();
        let (b, report) = decimate_scatter(&s, tris, &greedy).unwrap();
        assert_ne!(a, b, "the order made no difference");
        assert_eq!(report.sweeps, 1);
        assert!(worst_error(&s, &b) <= 1.0);
    }
}
