//! Retriangulation of the hole left by removing one vertex: the paper's ear selection
//! (§3.4, in [`ears`]) or the triangulation of least maximum error by dynamic programming
//! ([`dp`]), each new triangle's error either propagated from the star's bounds as the
//! paper does (§3.3, in [`propagation`]) or measured exactly over the samples it covers.
//!
//! The hole is the star of the removed vertex `c`: the ring `r_0 .. r_{m-1}` of its
//! neighbours, counter-clockwise. For an interior vertex the ring is closed and star
//! triangle `i` is `(c, r_i, r_{i+1 mod m})`; for a boundary vertex `c` lies on the domain
//! edge `r_{m-1} r_0` and star triangle `i` is `(c, r_i, r_{i+1})` for `i < m - 1`.

mod dp;
mod ears;
mod propagation;

use crate::coverage::Coverage;
use crate::exact::error_at;
use crate::predicates::{in_closed_triangle, orient, plane_gradient, Point};
use crate::{EdgeLimit, EdgeSelection, ErrorBound, ErrorModel, Grid, Retriangulation};
use dp::Solved;
use ears::Ear;

/// A triangle of the retriangulated hole: ring positions (counter-clockwise) and bound.
#[derive(Debug, Clone, Copy)]
pub(crate) struct HoleTriangle {
    pub corners: [u32; 3],
    pub bound: ErrorBound,
}

/// The bound and introduced error of one segment between ring vertices.
#[derive(Debug, Clone, Copy, Default)]
struct SegmentError {
    bound: ErrorBound,
    /// Largest |new - old| at the segment's entry and exit points (§3.4 "introduced").
    introduced: f64,
}

/// One variable's values on the loaded hole, as points with the hole's positions: the
/// ring's, the centre's, the star triangles' gradients and the factor into height units.
#[derive(Debug, Clone, Default)]
struct VariableLayer {
    ring: Vec<Point>,
    centre: Point,
    gradients: Vec<[f64; 2]>,
    scale: f64,
}

/// Reusable buffers for [`Retriangulator::retriangulate`]; one per thread.
#[derive(Debug, Default)]
pub(crate) struct Retriangulator {
    ring: Vec<Point>,
    star_bounds: Vec<ErrorBound>,
    star_gradients: Vec<[f64; 2]>,
    centre: Option<Point>,
    boundary: bool,
    /// Every star triangle is a half cell (doubled area 1), so the hole holds no sample
    /// but its ring vertices and the centre (Pick's theorem): a new triangle's exact error
    /// is measured at its corners and, when it contains it, the centre.
    unit_hole: bool,
    max_star_above: f64,
    max_star_below: f64,
    /// The variables' values on the hole (bounds model with several variables); the first
    /// `variable_count` are loaded, the rest are buffers kept for reuse.
    variable_layers: Vec<VariableLayer>,
    variable_count: usize,
    // Current polygon during ear clipping.
    prev: Vec<u32>,
    next: Vec<u32>,
    edge: Vec<SegmentError>,
    ears: Vec<Option<Option<Ear>>>,
    triangles: Vec<HoleTriangle>,
    /// Segment errors by ring index pair `i < j` (row-major m x m), for this hole.
    segments: Vec<Option<SegmentError>>,
    /// Exact errors of triangles tried in this hole, by sorted corner triple (`None`: over
    /// the limit).
    exact_errors: Vec<(u64, Option<ErrorBound>)>,
    // Dynamic programming tables, row-major m x m.
    /// Whether ring vertices `i < j` may be joined (a ring edge or a diagonal), once asked.
    diagonal: Vec<Option<bool>>,
    cost: Vec<f64>,
    cost_sum: Vec<f64>,
    split: Vec<u32>,
    /// Top-down DP: what `cost` holds for each interval (see [`Solved`]).
    solved: Vec<Solved>,
    /// Intervals still to rebuild after the DP.
    stack: Vec<(usize, usize)>,
}

/// What the retriangulation needs besides the hole: the rules and the samples the new
/// triangles must come within the bound of (a grid, or a hole's scattered points).
#[derive(Debug)]
pub(crate) struct Rules<'g, S: Coverage + ?Sized = Grid> {
    pub grid: &'g S,
    pub model: ErrorModel,
    pub selection: EdgeSelection,
    pub method: Retriangulation,
    /// Holes with more ring vertices than this use ears even when `method` is `Dp`.
    pub dp_max_ring: usize,
    pub limit: f64,
    /// The longest edge a new triangle may have.
    pub edge_limit: &'g EdgeLimit,
    /// Contour levels (sorted) the DP minimizes the spanned count of, if any.
    pub levels: Option<&'g [f64]>,
}

impl<S: Coverage + ?Sized> Clone for Rules<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S: Coverage + ?Sized> Copy for Rules<'_, S> {}

impl Retriangulator {
    /// Loads a hole: the removed vertex, its ring and the bounds of its star triangles
    /// (`ring.len()` of them for an interior vertex, `ring.len() - 1` for a boundary one).
    pub(crate) fn load(&mut self, centre: Point, ring: &[Point], star_bounds: &[ErrorBound]) {
        let boundary = star_bounds.len() + 1 == ring.len();
        debug_assert!(boundary || star_bounds.len() == ring.len());
        self.centre = Some(centre);
        self.boundary = boundary;
        self.variable_count = 0;
        self.ring.clear();
        self.ring.extend_from_slice(ring);
        self.star_bounds.clear();
        self.star_bounds.extend_from_slice(star_bounds);
        let m = ring.len();
        self.exact_errors.clear();
        self.unit_hole =
            (0..star_bounds.len()).all(|i| orient(&centre, &ring[i], &ring[(i + 1) % m]) == 1);
        self.max_star_above = star_bounds
            .iter()
            .fold(f64::NEG_INFINITY, |m, b| m.max(b.above));
        self.max_star_below = star_bounds
            .iter()
            .fold(f64::NEG_INFINITY, |m, b| m.max(b.below));
    }

    /// Triangulates the loaded hole under `rules`, accepting only triangles whose bound is
    /// at most `rules.limit` on both sides. Returns the triangles (corners index the ring)
    /// and the largest bound among them, or `None` on a dead end (paper §3.4).
    pub(crate) fn retriangulate<S: Coverage + ?Sized>(
        &mut self,
        rules: &Rules<'_, S>,
    ) -> Option<(&[HoleTriangle], f64)> {
        if !self.centre_can_fit(rules) {
            return None;
        }
        let dp = rules.method == Retriangulation::Dp && self.ring.len() <= rules.dp_max_ring;
        // The exact model's DP needs no segment errors; the rest does.
        if rules.model == ErrorModel::Bounds || !dp {
            self.prepare_segments();
        }
        let found = if dp {
            self.dynamic_programming(rules)
        } else {
            match rules.selection {
                EdgeSelection::Hybrid => {
                    self.clip_ears(EdgeSelection::MinIntroduced, rules)
                        || self.clip_ears(EdgeSelection::MinError, rules)
                }
                rule => self.clip_ears(rule, rules),
            }
        };
        if !found {
            return None;
        }
        let worst = self
            .triangles
            .iter()
            .fold(0.0f64, |w, t| w.max(t.bound.max()));
        Some((&self.triangles, worst))
    }

    /// A necessary condition, cheap to test: whatever the triangulation, the removed vertex
    /// lies in a triangle of ring vertices, and its own error there must be within the
    /// limit (both error models count it). Tries every such triangle for small rings.
    fn centre_can_fit<S: Coverage + ?Sized>(&self, rules: &Rules<'_, S>) -> bool {
        let limit = rules.limit;
        // Under the exact model a triangle holding the centre is refused when some
        // variable fails there (`Coverage::variables_refuse_at`, as the retriangulation
        // asks), so the condition holds for every field; the bounds model folds variables
        // into one bound, and keeps to the height's test here.
        let variables = rules.model == ErrorModel::Exact && rules.grid.has_variables();
        let m = self.ring.len();
        if m > 12 {
            return true;
        }
        let centre = self.centre.expect("hole loaded");
        // Triangle ijk contains the centre when each of its sides sees it on the left
        // (doubled areas of the centre with each side >= 0), and the triangle's own doubled
        // area is the sum of those three.
        for i in 0..m {
            let a = &self.ring[i];
            for j in i + 1..m {
                let b = &self.ring[j];
                let ab = orient(&centre, a, b);
                if ab < 0 {
                    continue;
                }
                for c in &self.ring[j + 1..] {
                    let (bc, ca) = (orient(&centre, b, c), orient(&centre, c, a));
                    if bc < 0 || ca < 0 || ab + bc + ca <= 0 {
                        continue;
                    }
                    debug_assert!(orient(a, b, c) > 0 && in_closed_triangle(a, b, c, &centre));
                    let g = plane_gradient(a, b, c);
                    let at = a.z + g[0] * (centre.x - a.x) as f64 + g[1] * (centre.y - a.y) as f64;
                    if (at - centre.z).abs() <= limit
                        && !(variables && rules.grid.variables_refuse_at(a, b, c, &centre, limit))
                    {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The bound of new triangle `abc` under the error model, if within the limit. For
    /// `Bounds`, `edges` are the bounds of its three edges (paper §3.3.3).
    fn triangle_cost<S: Coverage + ?Sized>(
        &mut self,
        a: usize,
        b: usize,
        c: usize,
        edges: [SegmentError; 3],
        rules: &Rules<'_, S>,
    ) -> Option<ErrorBound> {
        self.triangle_cost_capped([a, b, c], edges, rules, rules.limit, false)
    }

    /// [`Retriangulator::triangle_cost`] within `cap <= rules.limit`: `None` as soon as the
    /// error is known to exceed `cap` (the DP passes the best cost found so far).
    /// `in_hole` says the triangle is known to lie in the hole with no other ring vertex
    /// in it (its sides are ring edges or diagonals), as the DP's triangles do.
    fn triangle_cost_capped<S: Coverage + ?Sized>(
        &mut self,
        [a, b, c]: [usize; 3],
        edges: [SegmentError; 3],
        rules: &Rules<'_, S>,
        cap: f64,
        in_hole: bool,
    ) -> Option<ErrorBound> {
        let (pa, pb, pc) = (&self.ring[a], &self.ring[b], &self.ring[c]);
        if [(pa, pb), (pb, pc), (pc, pa)]
            .iter()
            .any(|(p, q)| !rules.edge_limit.allows(p, q))
            || !rules.edge_limit.faces_out(pa, pb, pc)
        {
            return None;
        }
        // At a cap of 0 on integer heights only the scan decides, exactly (see
        // `Grid::integral_heights`): no shortcut through f64 plane values.
        let scan_only = cap == 0.0 && rules.grid.integral_heights();
        let bound = match rules.model {
            ErrorModel::Bounds => self.triangle_bound(a, b, c, edges),
            ErrorModel::Exact
                if self.unit_hole && in_hole && !scan_only && !rules.grid.has_variables() =>
            {
                let centre = self.centre.expect("hole loaded");
                let inside = in_closed_triangle(pa, pb, pc, &centre);
                // The corners' samples: the vertices themselves unless heights are raised.
                let raised;
                let samples = if rules.grid.has_vertex_heights() {
                    raised = rules.grid.corner_samples([pa, pb, pc]);
                    [&raised[0], &raised[1], &raised[2], &centre]
                } else {
                    [pa, pb, pc, &centre]
                };
                let e = error_at(
                    pa,
                    pb,
                    pc,
                    samples[..3 + usize::from(inside)].iter().copied(),
                    cap,
                );
                // Equal values: a zero error may come out as 0.0 one way and -0.0 the other.
                debug_assert_eq!(
                    e.map(|b| (b.above, b.below)),
                    rules
                        .grid
                        .triangle_error(pa, pb, pc, cap)
                        .map(|b| (b.above, b.below)),
                    "a unit hole holds no other sample"
                );
                e?
            }
            ErrorModel::Exact => {
                let mut key = [a as u64, b as u64, c as u64];
                key.sort_unstable();
                let key = key[0] | key[1] << 21 | key[2] << 42;
                match self.exact_errors.iter().find(|e| e.0 == key) {
                    Some(&(_, cached)) => cached?,
                    None => {
                        // The removed vertex is a sample: where it lies in the triangle and
                        // alone passes the cap, the scan is not needed to say so (the same
                        // plane arithmetic as the scan's, so the same verdict).
                        let centre = self.centre.expect("hole loaded");
                        let e = if !scan_only
                            && in_closed_triangle(pa, pb, pc, &centre)
                            && (error_at(pa, pb, pc, [&centre], cap).is_none()
                                || rules.grid.variables_refuse_at(pa, pb, pc, &centre, cap))
                        {
                            None
                        } else {
                            rules.grid.triangle_error(pa, pb, pc, cap)
                        };
                        // "Over the cap" is only worth keeping when the cap is the limit.
                        if e.is_some() || cap >= rules.limit {
                            self.exact_errors.push((key, e));
                        }
                        e?
                    }
                }
            }
        };
        within(bound, cap).then_some(bound)
    }
}

fn within(bound: ErrorBound, limit: f64) -> bool {
    bound.above <= limit && bound.below <= limit
}

#[cfg(test)]
mod tests {
    use super::propagation::clip_segment;
    use super::*;
    use crate::exact::triangle_error;
    use crate::Variable;
    use tinsmith_georef::Samples;

    fn pt(x: i64, y: i64, z: f64) -> Point {
        Point { x, y, z }
    }

    fn rules(
        grid: &Grid,
        selection: EdgeSelection,
        method: Retriangulation,
        limit: f64,
    ) -> Rules<'_> {
        Rules {
            grid,
            model: ErrorModel::Bounds,
            selection,
            method,
            dp_max_ring: 16,
            limit,
            edge_limit: &crate::edge_limit::NO_EDGE_LIMIT,
            levels: None,
        }
    }

    fn unused_grid() -> Grid {
        Grid::new(1, 1, vec![0.0]).unwrap()
    }

    #[test]
    fn clipping_finds_entry_and_exit() {
        let tri = [pt(0, 0, 0.0), pt(4, 0, 0.0), pt(0, 4, 0.0)];
        let (lo, hi) = clip_segment(&pt(-1, 1, 0.0), &pt(5, 1, 0.0), &tri).unwrap();
        assert!((lo - 1.0 / 6.0).abs() < 1e-15 && (hi - 4.0 / 6.0).abs() < 1e-15);
        assert!(clip_segment(&pt(5, 5, 0.0), &pt(6, 5, 0.0), &tri).is_none());
        // Touching a corner counts (closed triangle).
        let (lo, hi) = clip_segment(&pt(-2, 2, 0.0), &pt(2, -2, 0.0), &tri).unwrap();
        assert_eq!((lo, hi), (0.5, 0.5));
    }

    #[test]
    fn removing_a_peak_counts_its_own_error() {
        // A peak of 10 in the middle of a flat square ring: removing it costs 10 below.
        let ring = [pt(0, 0, 0.0), pt(2, 0, 0.0), pt(2, 2, 0.0), pt(0, 2, 0.0)];
        let mut r = Retriangulator::default();
        r.load(pt(1, 1, 10.0), &ring, &[ErrorBound::default(); 4]);
        let g = unused_grid();
        for method in [Retriangulation::Ears, Retriangulation::Dp] {
            assert!(r
                .retriangulate(&rules(&g, EdgeSelection::Hybrid, method, 9.9))
                .is_none());
            let (tris, worst) = r
                .retriangulate(&rules(&g, EdgeSelection::Hybrid, method, 10.0))
                .unwrap();
            assert_eq!(tris.len(), 2);
            assert_eq!(worst, 10.0);
        }
    }

    #[test]
    fn a_variable_failing_at_the_centre_in_every_triangle_refuses_the_hole() {
        // Flat heights; a variable of 0 and 20 on alternate ring corners and 10 at the
        // centre: either diagonal puts 0 or 20 there, 10 away, though 10 lies within the
        // ring's range (so only the centre's own test, not the ring's range, refuses it).
        let height = Samples::new(3, 3, vec![0.0; 9]).unwrap();
        let mut values = vec![0.0; 9];
        values[2] = 20.0;
        values[6] = 20.0;
        values[4] = 10.0;
        let ring = [pt(0, 0, 0.0), pt(2, 0, 0.0), pt(2, 2, 0.0), pt(0, 2, 0.0)];
        let mut r = Retriangulator::default();
        r.load(pt(1, 1, 0.0), &ring, &[ErrorBound::default(); 4]);
        for (bound, fits) in [(9.5, false), (10.5, true)] {
            let variable = Variable::new(Samples::new(3, 3, values.clone()).unwrap(), bound);
            let grid = Grid::with_variables(height.clone(), vec![variable.unwrap()]).unwrap();
            let exact = Rules {
                model: ErrorModel::Exact,
                ..rules(&grid, EdgeSelection::Hybrid, Retriangulation::Dp, 5.0)
            };
            assert_eq!(r.centre_can_fit(&exact), fits, "bound {bound}");
            assert_eq!(r.retriangulate(&exact).is_some(), fits, "bound {bound}");
        }
    }

    #[test]
    fn planar_star_retriangulates_with_zero_error() {
        let f = |x: i64, y: i64| pt(x, y, 1.0 + x as f64);
        let ring = [
            f(0, 0),
            f(1, 0),
            f(2, 0),
            f(2, 1),
            f(2, 2),
            f(1, 2),
            f(0, 2),
            f(0, 1),
        ];
        let mut r = Retriangulator::default();
        r.load(f(1, 1), &ring, &[ErrorBound::default(); 8]);
        let g = unused_grid();
        for method in [Retriangulation::Ears, Retriangulation::Dp] {
            let (tris, worst) = r
                .retriangulate(&rules(&g, EdgeSelection::MinError, method, 0.0))
                .unwrap();
            assert_eq!((tris.len(), worst), (6, 0.0));
            for t in tris {
                let [a, b, c] = t.corners.map(|i| ring[i as usize]);
                assert!(orient(&a, &b, &c) > 0);
            }
        }
    }

    #[test]
    fn boundary_vertex_error_goes_to_the_new_edge() {
        // Boundary vertex (1,0) at height 4 on the straight edge from (0,0) to (2,0).
        let ring = [
            pt(2, 0, 0.0),
            pt(2, 1, 0.0),
            pt(1, 1, 0.0),
            pt(0, 1, 0.0),
            pt(0, 0, 0.0),
        ];
        let mut r = Retriangulator::default();
        r.load(pt(1, 0, 4.0), &ring, &[ErrorBound::default(); 4]);
        let g = unused_grid();
        for method in [Retriangulation::Ears, Retriangulation::Dp] {
            assert!(r
                .retriangulate(&rules(&g, EdgeSelection::Hybrid, method, 3.0))
                .is_none());
            let (tris, worst) = r
                .retriangulate(&rules(&g, EdgeSelection::Hybrid, method, 4.0))
                .unwrap();
            assert_eq!((tris.len(), worst), (3, 4.0));
        }
    }

    #[test]
    fn dp_is_never_worse_than_ears() {
        // DP minimizes the largest triangle bound over all triangulations; ears pick one.
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % 1000) as f64 / 100.0
        };
        let g = unused_grid();
        for _ in 0..50 {
            let ring: Vec<Point> = [
                (0, 0),
                (1, 0),
                (2, 0),
                (3, 1),
                (2, 2),
                (1, 3),
                (0, 2),
                (-1, 1),
            ]
            .iter()
            .map(|&(x, y)| pt(x, y, rnd()))
            .collect();
            let bounds: Vec<ErrorBound> = (0..8)
                .map(|_| ErrorBound {
                    above: rnd() / 10.0,
                    below: rnd() / 10.0,
                })
                .collect();
            let mut r = Retriangulator::default();
            r.load(pt(1, 1, rnd()), &ring, &bounds);
            let (_, dp) = r
                .retriangulate(&rules(
                    &g,
                    EdgeSelection::MinError,
                    Retriangulation::Dp,
                    1e9,
                ))
                .unwrap();
            for sel in [EdgeSelection::MinError, EdgeSelection::MinIntroduced] {
                let (_, ears) = r
                    .retriangulate(&rules(&g, sel, Retriangulation::Ears, 1e9))
                    .unwrap();
                // Equal up to rounding: a segment's error is computed from either end.
                assert!(dp <= ears + 1e-9 * (1.0 + ears), "dp {dp} > ears {ears}");
            }
        }
    }

    /// Every triangulation of ring interval `i..=j` as (largest exact error, summed
    /// errors), by plain enumeration; `None` errors (beyond `limit`) drop a triangulation.
    fn all_triangulations(
        r: &Retriangulator,
        g: &Grid,
        i: usize,
        j: usize,
        limit: f64,
    ) -> Vec<(f64, f64)> {
        if j == i + 1 {
            return vec![(0.0, 0.0)];
        }
        let mut out = Vec::new();
        let m = r.ring.len();
        let joins = |a: usize, b: usize| {
            b == a + 1 || (a == 0 && b == m - 1) || r.is_diagonal_general(a, b)
        };
        for k in i + 1..j {
            let (a, b, c) = (&r.ring[i], &r.ring[k], &r.ring[j]);
            if !joins(i, k) || !joins(k, j) || orient(a, b, c) <= 0 {
                continue;
            }
            let Some(t) = triangle_error(g, a, b, c, limit) else {
                continue;
            };
            for l in all_triangulations(r, g, i, k, limit) {
                for rr in all_triangulations(r, g, k, j, limit) {
                    out.push((l.0.max(rr.0).max(t.max()), l.1 + rr.1 + t.max()));
                }
            }
        }
        out
    }

    #[test]
    fn dp_finds_the_min_max_triangulation_or_none() {
        // Exact errors on a random grid, holes convex and reflex, at limits around each
        // hole's optimum: the DP must agree with an enumeration of all triangulations.
        let mut seed = 11u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) % 1000
        };
        let rings: [&[(i64, i64)]; 3] = [
            &[
                (3, 3),
                (5, 2),
                (7, 3),
                (8, 5),
                (7, 7),
                (5, 8),
                (3, 7),
                (2, 5),
            ],
            &[(2, 2), (8, 2), (8, 8), (6, 8), (5, 6), (4, 8), (2, 8)],
            &[
                (2, 2),
                (4, 1),
                (6, 2),
                (8, 1),
                (9, 4),
                (8, 8),
                (6, 9),
                (4, 7),
                (2, 9),
                (1, 5),
            ],
        ];
        let (mut found, mut refused) = (0, 0);
        for trial in 0..300 {
            let values = (0..121).map(|_| rnd() as f64 / 100.0).collect();
            let g = Grid::new(11, 11, values).unwrap();
            let at = |(x, y): (i64, i64)| pt(x, y, g.get(x as u32, y as u32).unwrap());
            let ring: Vec<Point> = rings[trial % 3].iter().map(|&p| at(p)).collect();
            let mut r = Retriangulator::default();
            r.load(at((5, 5)), &ring, &vec![ErrorBound::default(); ring.len()]);
            let all = all_triangulations(&r, &g, 0, ring.len() - 1, f64::INFINITY);
            let best = all
                .iter()
                .copied()
                .fold((f64::INFINITY, f64::INFINITY), |b, t| {
                    if t.0 < b.0 || (t.0 == b.0 && t.1 < b.1) {
                        t
                    } else {
                        b
                    }
                });
            for limit in [
                best.0,
                best.0 - 1e-9,
                best.0 + 0.3,
                best.0 + 1.0,
                best.0 * 0.5,
            ] {
                let rules = Rules {
                    model: ErrorModel::Exact,
                    ..rules(&g, EdgeSelection::MinError, Retriangulation::Dp, limit)
                };
                match r.retriangulate(&rules) {
                    Some((triangles, worst)) => {
                        assert!(limit >= best.0, "found within {limit} < optimum {}", best.0);
                        assert_eq!(worst, best.0);
                        // The summed error only breaks ties interval by interval, so it
                        // need not be the least over all min-max triangulations.
                        let sum: f64 = triangles.iter().map(|t| t.bound.max()).sum();
                        assert!(sum >= best.1 - 1e-9 * (1.0 + best.1));
                        found += 1;
                    }
                    None => {
                        assert!(limit < best.0, "none within {limit} >= optimum {}", best.0);
                        refused += 1;
                    }
                }
            }
        }
        assert!(
            found >= 500 && refused >= 500,
            "{found} found, {refused} refused"
        );
    }

    #[test]
    fn diagonals_of_a_reflex_hole() {
        // An arrow-shaped ring around (2, 2): the reflex vertex (2, 3) blocks (1,4)-(3,4).
        let ring =
            [(0, 0), (4, 0), (4, 4), (3, 4), (2, 3), (1, 4), (0, 4)].map(|(x, y)| pt(x, y, 0.0));
        let mut r = Retriangulator::default();
        r.load(pt(2, 2, 0.0), &ring, &[ErrorBound::default(); 7]);
        assert!(r.is_diagonal(0, 2));
        assert!(r.is_diagonal(0, 4));
        assert!(!r.is_diagonal(3, 5), "passes outside at the reflex vertex");
        assert!(
            !r.is_diagonal(3, 6),
            "passes through the reflex vertex's outside"
        );
        for i in 0..7 {
            for j in i + 2..7 {
                if (i, j) != (0, 6) {
                    assert_eq!(
                        r.is_diagonal(i, j),
                        r.is_diagonal_general(i, j),
                        "({i}, {j})"
                    );
                }
            }
        }
    }

    #[test]
    fn star_diagonal_test_agrees_with_the_general_one() {
        // Random star-shaped rings around the origin, interior and boundary.
        let mut seed = 11u64;
        let mut rnd = |n: i64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) as i64).rem_euclid(n)
        };
        let mut checked = 0;
        for case in 0..2000 {
            let boundary = case % 2 == 1;
            let m = 3 + rnd(8) as usize;
            let span = if boundary {
                std::f64::consts::PI
            } else {
                2.0 * std::f64::consts::PI
            };
            let mut ring: Vec<Point> = Vec::new();
            for k in 0..m {
                // Angles spread over the full turn (interior) or the upper half (boundary).
                let t = span * (k as f64 + 0.1 + 0.8 * rnd(100) as f64 / 100.0) / m as f64;
                let t = match (boundary, k) {
                    (true, 0) => 0.0,
                    (true, k) if k == m - 1 => span,
                    _ => t,
                };
                let r = 2.0 + rnd(6) as f64;
                ring.push(pt(
                    (r * t.cos()).round() as i64,
                    (r * t.sin()).round() as i64,
                    0.0,
                ));
            }
            let centre = pt(0, 0, 0.0);
            let stars = if boundary { m - 1 } else { m };
            let star_ok = (0..stars).all(|i| orient(&centre, &ring[i], &ring[(i + 1) % m]) > 0)
                && (!boundary || orient(&ring[m - 1], &centre, &ring[0]) == 0);
            if !star_ok {
                continue;
            }
            let mut r = Retriangulator::default();
            r.load(centre, &ring, &vec![ErrorBound::default(); stars]);
            for i in 0..m {
                for j in i + 2..m {
                    if (i, j) != (0, m - 1) {
                        checked += 1;
                        assert_eq!(
                            r.is_diagonal(i, j),
                            r.is_diagonal_general(i, j),
                            "{ring:?} ({i}, {j})"
                        );
                    }
                }
            }
        }
        assert!(checked > 1000, "only {checked} pairs checked");
    }
}
