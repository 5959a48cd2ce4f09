//! Removing one vertex: planning its hole's retriangulation and applying it, and the
//! forced removal of a tile's skipped border samples.

use crate::hole::{Retriangulator, Rules};
use crate::levels::triangle_levels;
use crate::mesh::{Mesh, Star, VertexClass, NONE};
use crate::predicates::Point;
use crate::{Error, ErrorBound, ErrorModel, Result};

/// Removes every valid border sample that `keep` rejects (grid corners are kept), in
/// row-major order along each side, with triangles inside the border strip.
pub(super) fn remove_border(
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

/// The largest hole (ring vertices) decimation retriangulates; vertices with more
/// neighbours stay. Removing a line of vertices one after another can hand each one's hole
/// on to the next, so rings grow with the line and ear clipping, cubic in the ring, took
/// most of the time (ETOPO5 at 100 m in tiles of 2048: rings up to 706, 25.6 s; capped at
/// 64: 8.8 s). Measured on ETOPO5, Big Tujunga, a CT slice and Vinschgau at 5 to 100: the
/// cap changes triangle counts by at most 0.002 %.
const MAX_HOLE_RING: usize = 64;

/// Removes single vertices; holds the buffers reused across attempts.
pub(crate) struct Remover<'g> {
    pub(super) star: Star,
    ring_star: Star,
    hole: Retriangulator,
    points: Vec<Point>,
    bounds: Vec<ErrorBound>,
    new_triangles: Vec<(u32, [u32; 3], ErrorBound)>,
    pub(crate) rules: Rules<'g>,
    /// In border mode, `(width, height)`: samples on the grid's outer border stay.
    pub(super) locked_border: Option<(u32, u32)>,
    /// Vertices with more neighbours than this are not tried (see [`MAX_HOLE_RING`]).
    max_ring: usize,
    /// With contour levels: refuse a removal whose new triangles span more levels in all
    /// than the star's did (it would give the contour lines more segments).
    pub(super) segments_may_not_grow: bool,
    /// Slots of border-fan triangles made by [`Remover::force_remove`] whose errors are
    /// measured once the border is done ([`Remover::measure_border_fans`]): along a run of
    /// skipped border samples each fan's last triangle spans the whole run so far and is
    /// replaced by the next removal, so measuring it each time would be quadratic.
    unmeasured_fans: Vec<u32>,
}

impl<'g> Remover<'g> {
    pub(super) fn new(rules: Rules<'g>) -> Remover<'g> {
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
        self.max_ring = usize::MAX;
        // Within the run's edge limit (lengths and, on a sphere, faces) where the hole
        // allows it; else with none, the caller's 1-D rule having spaced the kept border
        // samples.
        let mut planned = None;
        for edge_limit in [saved.edge_limit, &crate::edge_limit::NO_EDGE_LIMIT] {
            self.rules = Rules {
                model: crate::ErrorModel::Exact,
                selection: crate::EdgeSelection::MinError,
                method: crate::Retriangulation::Ears,
                // Exactly planar holes only, decided exactly, at a bound of 0 on integer
                // heights.
                limit: if exact_zero { 0.0 } else { f64::INFINITY },
                edge_limit,
                ..saved
            };
            planned = self.plan(mesh, v);
            if planned.is_some() {
                break;
            }
        }
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
        if self.rules.grid.variable_count() > 0
            && (crate::variables::centre_outside_ring(self.rules.grid, &centre, &self.points)
                || (self.rules.model == ErrorModel::Bounds
                    && crate::variables::held_variable_not_flat(
                        self.rules.grid,
                        &centre,
                        &self.points,
                    )))
        {
            return None;
        }
        self.bounds.clear();
        self.bounds
            .extend(star.triangles.iter().map(|&t| mesh.bound(t)));
        self.hole.load(centre, &self.points, &self.bounds);
        if self.rules.model == ErrorModel::Bounds && self.rules.grid.variable_count() > 0 {
            self.hole.load_variables(self.rules.grid);
        }
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
