//! Retriangulation of the hole left by removing one vertex, with the paper's error
//! propagation (§3.3) and ear selection (§3.4).
//!
//! The hole is the star of the removed vertex `c`: the ring `r_0 .. r_{m-1}` of its
//! neighbours, counter-clockwise. For an interior vertex the ring is closed and star
//! triangle `i` is `(c, r_i, r_{i+1 mod m})`; for a boundary vertex `c` lies on the domain
//! edge `r_{m-1} r_0` and star triangle `i` is `(c, r_i, r_{i+1})` for `i < m - 1`.
//!
//! # Error propagation
//! Each star triangle `T` carries an [`ErrorBound`] valid for every original sample in it.
//! For a new triangle `N`, every sample in `N ∩ T` satisfies
//! `sample - new ≤ T.above - min δ` and `new - sample ≤ T.below + max δ`, where
//! `δ = new - old` is linear on the convex polygon `N ∩ T`, so its extremes sit at that
//! polygon's corners. Those corners are (a) the entry and exit points of `N`'s edges in `T`
//! (the paper's §3.3.1 rule, computed here by exact clipping of each edge against each
//! closed star triangle), and (b) the removed vertex `c` when it lies in `N`.
//!
//! Case (b) is not in the paper, which propagates errors along edges only. Without it the
//! removed vertex's own error is not counted (a peak removed from the middle of its ring
//! is lower than its ring's chords suggest), and for a boundary vertex only the two
//! outermost star triangles would feed the new boundary edge. Counting (b) keeps the
//! bound a true bound; the paper's boundary rule (§3.3.2) is the special case of (a) and
//! (b) on the new boundary edge, which passes through `c`.

use crate::exact::{corner_samples, error_at, triangle_error};
use crate::levels::{dirichlet_energy, triangle_levels};
use crate::predicates::{in_closed_triangle, orient, plane_gradient, Point};
use crate::{EdgeSelection, ErrorBound, ErrorModel, Grid, Retriangulation};

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

/// An ear at ring vertex `q`, cutting off `(prev q, q, next q)`.
#[derive(Debug, Clone, Copy)]
struct Ear {
    diagonal: SegmentError,
    triangle: ErrorBound,
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

/// How much the top-down DP knows about an interval's optimum.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Solved {
    /// Not yet asked.
    Unknown,
    /// `cost`, `cost_sum` and `split` hold the optimum (`split == u32::MAX`: no
    /// triangulation within the limit).
    Exact,
    /// The optimum's largest error exceeds the value in `cost`.
    Above,
}

/// What the retriangulation needs besides the hole: the rules and the grid.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rules<'g> {
    pub grid: &'g Grid,
    pub model: ErrorModel,
    pub selection: EdgeSelection,
    pub method: Retriangulation,
    /// Holes with more ring vertices than this use ears even when `method` is `Dp`.
    pub dp_max_ring: usize,
    pub limit: f64,
    /// Largest squared edge length (in sample spacings) a new triangle may have.
    pub max_edge_squared: i64,
    /// Contour levels (sorted) the DP minimizes the spanned count of, if any.
    pub levels: Option<&'g [f64]>,
}

impl Retriangulator {
    /// Loads a hole: the removed vertex, its ring and the bounds of its star triangles
    /// (`ring.len()` of them for an interior vertex, `ring.len() - 1` for a boundary one).
    pub(crate) fn load(&mut self, centre: Point, ring: &[Point], star_bounds: &[ErrorBound]) {
        let boundary = star_bounds.len() + 1 == ring.len();
        debug_assert!(boundary || star_bounds.len() == ring.len());
        self.centre = Some(centre);
        self.boundary = boundary;
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
    pub(crate) fn retriangulate(&mut self, rules: &Rules<'_>) -> Option<(&[HoleTriangle], f64)> {
        if !self.centre_can_fit(rules.limit) {
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

    /// The star triangles' gradients and an empty table of segment errors, for the error
    /// propagation of §3.3 and the ears' introduced error.
    fn prepare_segments(&mut self) {
        let centre = self.centre.expect("hole loaded");
        let m = self.ring.len();
        self.segments.clear();
        self.segments.resize(m * m, None);
        self.star_gradients.clear();
        for i in 0..self.star_bounds.len() {
            let g = plane_gradient(&centre, &self.ring[i], &self.ring[(i + 1) % m]);
            self.star_gradients.push(g);
        }
    }

    /// A necessary condition, cheap to test: whatever the triangulation, the removed vertex
    /// lies in a triangle of ring vertices, and its own error there must be within the
    /// limit (both error models count it). Tries every such triangle for small rings.
    fn centre_can_fit(&self, limit: f64) -> bool {
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
                    if (at - centre.z).abs() <= limit {
                        return true;
                    }
                }
            }
        }
        false
    }

    fn clip_ears(&mut self, rule: EdgeSelection, rules: &Rules<'_>) -> bool {
        let m = self.ring.len();
        self.triangles.clear();
        self.prev.clear();
        self.next.clear();
        self.edge.clear();
        self.ears.clear();
        for i in 0..m {
            self.prev.push(((i + m - 1) % m) as u32);
            self.next.push(((i + 1) % m) as u32);
            let e = self.ring_edge_error(i);
            self.edge.push(e);
            self.ears.push(None);
        }
        let mut remaining = m;
        let mut start = 0usize;
        while remaining > 3 {
            let mut best: Option<(usize, f64)> = None;
            let mut q = start;
            for _ in 0..remaining {
                if self.ears[q].is_none() {
                    let ear = self.ear(q, rules);
                    self.ears[q] = Some(ear);
                }
                // Geometric validity can change as other vertices leave the polygon, so it
                // is re-tested every round; the error part is cached per ear.
                if let Some(Some(ear)) = self.ears[q] {
                    if self.ear_is_empty(q) {
                        let key = match (rule, rules.model) {
                            (EdgeSelection::MinIntroduced, _) => ear.diagonal.introduced,
                            (_, ErrorModel::Bounds) => ear.diagonal.bound.max(),
                            (_, ErrorModel::Exact) => ear.triangle.max(),
                        };
                        if best.is_none_or(|(_, k)| key < k) {
                            best = Some((q, key));
                        }
                    }
                }
                q = self.next[q] as usize;
            }
            let Some((q, _)) = best else { return false };
            let Some(Some(ear)) = self.ears[q] else {
                return false;
            };
            let (p, r) = (self.prev[q] as usize, self.next[q] as usize);
            self.triangles.push(HoleTriangle {
                corners: [p as u32, q as u32, r as u32],
                bound: ear.triangle,
            });
            self.next[p] = r as u32;
            self.prev[r] = p as u32;
            self.edge[p] = ear.diagonal;
            self.ears[p] = None;
            self.ears[r] = None;
            remaining -= 1;
            start = p;
        }
        let a = start;
        let (b, c) = (
            self.next[a] as usize,
            self.next[self.next[a] as usize] as usize,
        );
        if orient(&self.ring[a], &self.ring[b], &self.ring[c]) <= 0 {
            return false;
        }
        let Some(bound) =
            self.triangle_cost(a, b, c, [self.edge[a], self.edge[b], self.edge[c]], rules)
        else {
            return false;
        };
        self.triangles.push(HoleTriangle {
            corners: [a as u32, b as u32, c as u32],
            bound,
        });
        true
    }

    /// The ear at `q` if it is convex and its triangle's bound is within the limit.
    fn ear(&mut self, q: usize, rules: &Rules<'_>) -> Option<Ear> {
        let (p, r) = (self.prev[q] as usize, self.next[q] as usize);
        if orient(&self.ring[p], &self.ring[q], &self.ring[r]) <= 0 {
            return None;
        }
        // The exact model needs the diagonal only for its introduced error.
        let needs_diagonal =
            rules.model == ErrorModel::Bounds || rules.selection != EdgeSelection::MinError;
        let diagonal = if needs_diagonal {
            self.segment(p.min(r), p.max(r))
        } else {
            SegmentError::default()
        };
        let triangle =
            self.triangle_cost(p, q, r, [self.edge[p], self.edge[q], diagonal], rules)?;
        Some(Ear { diagonal, triangle })
    }

    /// The bound of new triangle `abc` under the error model, if within the limit. For
    /// `Bounds`, `edges` are the bounds of its three edges (paper §3.3.3).
    fn triangle_cost(
        &mut self,
        a: usize,
        b: usize,
        c: usize,
        edges: [SegmentError; 3],
        rules: &Rules<'_>,
    ) -> Option<ErrorBound> {
        self.triangle_cost_capped([a, b, c], edges, rules, rules.limit, false)
    }

    /// [`Retriangulator::triangle_cost`] within `cap <= rules.limit`: `None` as soon as the
    /// error is known to exceed `cap` (the DP passes the best cost found so far).
    /// `in_hole` says the triangle is known to lie in the hole with no other ring vertex
    /// in it (its sides are ring edges or diagonals), as the DP's triangles do.
    fn triangle_cost_capped(
        &mut self,
        [a, b, c]: [usize; 3],
        edges: [SegmentError; 3],
        rules: &Rules<'_>,
        cap: f64,
        in_hole: bool,
    ) -> Option<ErrorBound> {
        let (pa, pb, pc) = (&self.ring[a], &self.ring[b], &self.ring[c]);
        if [(pa, pb), (pb, pc), (pc, pa)]
            .iter()
            .any(|(p, q)| squared_length(p, q) > rules.max_edge_squared)
        {
            return None;
        }
        // At a cap of 0 on integer heights only the scan decides, exactly (see
        // `Grid::integral_heights`): no shortcut through f64 plane values.
        let scan_only = cap == 0.0 && rules.grid.integral_heights();
        let bound = match rules.model {
            ErrorModel::Bounds => self.triangle_bound(a, b, c, edges),
            ErrorModel::Exact if self.unit_hole && in_hole && !scan_only => {
                let centre = self.centre.expect("hole loaded");
                let inside = in_closed_triangle(pa, pb, pc, &centre);
                // The corners' samples: the vertices themselves unless heights are raised.
                let raised;
                let samples = if rules.grid.has_vertex_heights() {
                    raised = corner_samples(rules.grid, [pa, pb, pc]);
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
                debug_assert_eq!(
                    e.map(|b| (b.above.to_bits(), b.below.to_bits())),
                    triangle_error(rules.grid, pa, pb, pc, cap)
                        .map(|b| (b.above.to_bits(), b.below.to_bits())),
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
                            && error_at(pa, pb, pc, [&centre], cap).is_none()
                        {
                            None
                        } else {
                            triangle_error(rules.grid, pa, pb, pc, cap)
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

    /// Min-max-error triangulation of the hole by dynamic programming over ring intervals:
    /// `cost(i, j) = min over k of max(cost(i, k), cost(k, j), error(i, k, j))`, optimal for
    /// the error model (with levels: the fewest levels spanned among triangulations within
    /// the limit). Ties within an interval go to the smallest summed error (least Dirichlet
    /// energy), then the smallest `k`. Solved top-down from the whole ring (see
    /// [`Retriangulator::solve_interval`]).
    fn dynamic_programming(&mut self, rules: &Rules<'_>) -> bool {
        let m = self.ring.len();
        self.triangles.clear();
        self.diagonal.clear();
        self.diagonal.resize(m * m, None);
        self.cost.clear();
        self.cost.resize(m * m, f64::INFINITY);
        self.cost_sum.clear();
        self.cost_sum.resize(m * m, 0.0);
        self.split.clear();
        self.split.resize(m * m, u32::MAX);
        self.solved.clear();
        self.solved.resize(m * m, Solved::Unknown);
        let cap = match rules.levels {
            Some(_) => f64::INFINITY,
            None => rules.limit,
        };
        if self.solve_interval(0, m - 1, cap, rules).is_none() {
            return false;
        }
        // Rebuild the triangles, recomputing each one's bound.
        let mut stack = std::mem::take(&mut self.stack);
        stack.clear();
        stack.push((0usize, m - 1));
        while let Some((i, j)) = stack.pop() {
            if j < i + 2 {
                continue;
            }
            let k = self.split[i * m + j] as usize;
            let edges = match rules.model {
                ErrorModel::Bounds => [self.segment(i, k), self.segment(k, j), self.segment(i, j)],
                ErrorModel::Exact => [SegmentError::default(); 3],
            };
            let bound = self
                .triangle_cost_capped([i, k, j], edges, rules, rules.limit, true)
                .expect("chosen triangle is within the limit");
            self.triangles.push(HoleTriangle {
                corners: [i as u32, k as u32, j as u32],
                bound,
            });
            stack.push((k, j));
            stack.push((i, k));
        }
        self.stack = stack;
        true
    }

    /// The min-max optimum (largest error, then summed error, ties to the smallest split)
    /// of interval `i < j`, if its largest error is at most `cap`; memoized in `solved`.
    /// With levels, costs are level counts and `cap` bounds them instead.
    ///
    /// A sub-interval is only explored through a split triangle within the cap, and only
    /// asked for what could still beat the best split so far, so a hole that cannot be
    /// triangulated is usually refuted after few triangles, where filling the whole table
    /// bottom-up measured them all (15-18 % of the decimation's time, same output).
    fn solve_interval(
        &mut self,
        i: usize,
        j: usize,
        cap: f64,
        rules: &Rules<'_>,
    ) -> Option<(f64, f64)> {
        let m = self.ring.len();
        if j == i + 1 {
            return Some((0.0, 0.0));
        }
        let at = i * m + j;
        match self.solved[at] {
            Solved::Exact => {
                let found = self.split[at] != u32::MAX && self.cost[at] <= cap;
                return found.then_some((self.cost[at], self.cost_sum[at]));
            }
            Solved::Above if cap <= self.cost[at] => return None,
            _ => {}
        }
        let mut best = (f64::INFINITY, f64::INFINITY, u32::MAX);
        let joinable = self.joinable(i, j);
        if joinable {
            for k in i + 1..j {
                if !self.joinable(i, k) || !self.joinable(k, j) {
                    continue;
                }
                if orient(&self.ring[i], &self.ring[k], &self.ring[j]) <= 0 {
                    continue;
                }
                let spanned = rules.levels.map(|levels| {
                    let (pi, pk, pj) = (&self.ring[i], &self.ring[k], &self.ring[j]);
                    (
                        triangle_levels(levels, pi, pk, pj) as f64,
                        dirichlet_energy(pi, pk, pj),
                    )
                });
                // With levels the sub-intervals only add levels: a triangle spanning more
                // than the best cannot win, and needs no error.
                if spanned.is_some_and(|(n, _)| n > best.0) {
                    continue;
                }
                // Sub-intervals costlier than the best cannot win (costs only grow). With
                // levels, costs are level counts and the error is only a limit.
                let within = cap.min(best.0);
                let triangle_cap = match rules.levels {
                    Some(_) => rules.limit,
                    None => within,
                };
                let edges = match rules.model {
                    ErrorModel::Bounds => {
                        [self.segment(i, k), self.segment(k, j), self.segment(i, j)]
                    }
                    ErrorModel::Exact => [SegmentError::default(); 3],
                };
                let Some(t) =
                    self.triangle_cost_capped([i, k, j], edges, rules, triangle_cap, true)
                else {
                    continue;
                };
                let Some(left) = self.solve_interval(i, k, within, rules) else {
                    continue;
                };
                let Some(right) = self.solve_interval(k, j, within, rules) else {
                    continue;
                };
                let (c, sum) = match spanned {
                    Some((n, energy)) => (left.0 + right.0 + n, left.1 + right.1 + energy),
                    None => (left.0.max(right.0).max(t.max()), left.1 + right.1 + t.max()),
                };
                if c < best.0 || (c == best.0 && sum < best.1) {
                    best = (c, sum, k as u32);
                }
            }
        }
        let uncapped = match rules.levels {
            Some(_) => cap == f64::INFINITY,
            None => cap >= rules.limit,
        };
        // With levels a sum of children within the cap can exceed it; a result above the
        // cap came from a search pruned at the cap, so it is only a bound.
        if (best.2 != u32::MAX && best.0 <= cap) || uncapped || !joinable {
            self.solved[at] = Solved::Exact;
            self.cost[at] = best.0;
            self.cost_sum[at] = best.1;
            self.split[at] = best.2;
            (best.2 != u32::MAX).then_some((best.0, best.1))
        } else {
            self.solved[at] = Solved::Above;
            self.cost[at] = cap;
            None
        }
    }

    /// Whether ring vertices `i < j` may be joined by a new triangle's side: a ring edge
    /// (the open ring's ends included) or a diagonal of the hole. Memoized.
    fn joinable(&mut self, i: usize, j: usize) -> bool {
        let m = self.ring.len();
        if let Some(ok) = self.diagonal[i * m + j] {
            return ok;
        }
        let ok = j == i + 1 || (i == 0 && j == m - 1) || self.is_diagonal(i, j);
        self.diagonal[i * m + j] = Some(ok);
        ok
    }

    /// The cached error of the segment between ring vertices `i < j` (a ring edge or a
    /// diagonal).
    fn segment(&mut self, i: usize, j: usize) -> SegmentError {
        let m = self.ring.len();
        if let Some(e) = self.segments[i * m + j] {
            return e;
        }
        let e = if j == i + 1 {
            self.ring_edge_error(i)
        } else if i == 0 && j == m - 1 {
            self.ring_edge_error(m - 1)
        } else {
            self.segment_error(j, i)
        };
        self.segments[i * m + j] = Some(e);
        e
    }

    /// Whether the segment between ring vertices `i` and `j` (not neighbours) is a diagonal
    /// of the hole polygon: inside it and touching its boundary only at its ends. Exact.
    fn is_diagonal(&self, i: usize, j: usize) -> bool {
        // The hole is star-shaped from the removed vertex c, ring sorted around it. With c
        // strictly left of r_i -> r_j, the segment crosses exactly the spokes of the ring
        // vertices strictly between i and j (counter-clockwise), and lies in the hole iff
        // it crosses each of them strictly between c and its ring vertex, that is iff those
        // vertices lie strictly right of it. Through c, the segment is two half-spokes.
        let m = self.ring.len();
        let (i, j) = if i < j { (i, j) } else { (j, i) };
        let centre = self.centre.expect("hole loaded");
        let (a, b) = (&self.ring[i], &self.ring[j]);
        match orient(a, b, &centre).cmp(&0) {
            std::cmp::Ordering::Greater => (i + 1..j).all(|k| orient(a, b, &self.ring[k]) < 0),
            std::cmp::Ordering::Less => {
                !self.boundary
                    && (j + 1..m)
                        .chain(0..i)
                        .all(|k| orient(a, b, &self.ring[k]) > 0)
            }
            std::cmp::Ordering::Equal => !self.boundary,
        }
    }

    /// The general test, for any simple polygon: no crossing of a polygon edge, inside the
    /// corner cones at both ends. Checks [`Retriangulator::is_diagonal`] in the tests.
    #[cfg(test)]
    fn is_diagonal_general(&self, i: usize, j: usize) -> bool {
        let m = self.ring.len();
        let (a, b) = (&self.ring[i], &self.ring[j]);
        for k in 0..m {
            let k1 = (k + 1) % m;
            if k == i || k == j || k1 == i || k1 == j {
                continue;
            }
            if segments_meet(a, b, &self.ring[k], &self.ring[k1]) {
                return false;
            }
        }
        // Collinear with an edge at its end, or leaving the polygon at i.
        in_cone(&self.ring[(i + m - 1) % m], a, &self.ring[(i + 1) % m], b)
            && in_cone(&self.ring[(j + m - 1) % m], b, &self.ring[(j + 1) % m], a)
    }

    /// Whether no other vertex of the current polygon lies in the closed ear at `q`.
    fn ear_is_empty(&self, q: usize) -> bool {
        let (p, r) = (self.prev[q] as usize, self.next[q] as usize);
        let (a, b, c) = (&self.ring[p], &self.ring[q], &self.ring[r]);
        let mut s = self.next[r] as usize;
        while s != p {
            if in_closed_triangle(a, b, c, &self.ring[s]) {
                return false;
            }
            s = self.next[s] as usize;
        }
        true
    }

    /// Bound of new triangle `abc` from its edges' bounds and, when the removed vertex lies
    /// in it, from the removed vertex's own error against every star triangle.
    fn triangle_bound(&self, a: usize, b: usize, c: usize, edges: [SegmentError; 3]) -> ErrorBound {
        let mut bound = edges[0].bound;
        for e in &edges[1..] {
            bound.above = bound.above.max(e.bound.above);
            bound.below = bound.below.max(e.bound.below);
        }
        let centre = self.centre.expect("hole loaded");
        let (pa, pb, pc) = (&self.ring[a], &self.ring[b], &self.ring[c]);
        if in_closed_triangle(pa, pb, pc, &centre) {
            let g = plane_gradient(pa, pb, pc);
            let new_at_centre =
                pa.z + g[0] * (centre.x - pa.x) as f64 + g[1] * (centre.y - pa.y) as f64;
            let delta = new_at_centre - centre.z;
            bound.above = bound.above.max(self.max_star_above - delta);
            bound.below = bound.below.max(self.max_star_below + delta);
        }
        bound
    }

    /// Error of the segment from ring vertex `from` to ring vertex `to`: for each closed
    /// star triangle it meets, the signed introduced error at its entry and exit points
    /// folded into that triangle's bound (paper §3.3.1).
    fn segment_error(&self, from: usize, to: usize) -> SegmentError {
        let centre = self.centre.expect("hole loaded");
        let (p, q) = (self.ring[from], self.ring[to]);
        let m = self.ring.len();
        let stars = self.star_bounds.len();
        let mut out = SegmentError {
            bound: ErrorBound {
                above: f64::NEG_INFINITY,
                below: f64::NEG_INFINITY,
            },
            introduced: 0.0,
        };
        // A diagonal of the (star-shaped) hole splits it in two; it crosses the spokes of
        // the chain on the far side from the centre and touches the two star triangles
        // beyond its ends at a shared corner. Walking it with the centre on its left, the
        // introduced error is linear between consecutive spoke crossings, so each crossed
        // triangle's extremes are at the crossings on its two spokes.
        let side = orient(&p, &q, &centre);
        if side != 0 {
            let (a, b) = if side > 0 { (from, to) } else { (to, from) };
            let (p, q) = (self.ring[a], self.ring[b]);
            let side = side.abs() as f64;
            let span = (b + m - a) % m;
            let mut previous = 0.0f64; // introduced error at the last crossing (0 at p)
            let fold = |i: usize, lo: f64, hi: f64, out: &mut SegmentError| {
                if i < stars {
                    let bound = &self.star_bounds[i];
                    out.bound.above = out.bound.above.max(bound.above - lo);
                    out.bound.below = out.bound.below.max(bound.below + hi);
                }
            };
            fold((a + m - 1) % m, 0.0, 0.0, &mut out);
            for step in 1..=span {
                let k = (a + step) % m;
                let current = if step == span {
                    0.0
                } else {
                    let r = &self.ring[k];
                    let (fp, fq) = (orient(&centre, r, &p) as f64, orient(&centre, r, &q) as f64);
                    let t = fp / (fp - fq);
                    let u = side / (side - orient(&p, &q, r) as f64);
                    let new = p.z + t * (q.z - p.z);
                    let old = centre.z + u * (r.z - centre.z);
                    new - old
                };
                let i = (k + m - 1) % m;
                fold(i, previous.min(current), previous.max(current), &mut out);
                out.introduced = out.introduced.max(current.abs());
                previous = current;
            }
            fold(b, 0.0, 0.0, &mut out);
            debug_assert!(out.bound.above.is_finite(), "a ring segment meets its star");
            return out;
        }
        // The centre is on the segment: it touches every star triangle there.
        for i in 0..m.min(stars) {
            let (star_bound, g) = (&self.star_bounds[i], &self.star_gradients[i]);
            let tri = [centre, self.ring[i], self.ring[(i + 1) % m]];
            let Some((t_lo, t_hi)) = clip_segment(&p, &q, &tri) else {
                continue;
            };
            let delta = |t: f64| {
                let sx = p.x as f64 + t * (q.x - p.x) as f64;
                let sy = p.y as f64 + t * (q.y - p.y) as f64;
                let new = p.z + t * (q.z - p.z);
                let old = centre.z + g[0] * (sx - centre.x as f64) + g[1] * (sy - centre.y as f64);
                new - old
            };
            let (d0, d1) = (delta(t_lo), delta(t_hi));
            let (lo, hi) = (d0.min(d1), d0.max(d1));
            out.bound.above = out.bound.above.max(star_bound.above - lo);
            out.bound.below = out.bound.below.max(star_bound.below + hi);
            out.introduced = out.introduced.max(lo.abs()).max(hi.abs());
        }
        debug_assert!(out.bound.above.is_finite(), "a ring segment meets its star");
        out
    }

    /// Error of ring edge `i` (from ring vertex `i` to the next): the surface does not
    /// change along it, so it carries the bounds of the star triangles that contain it or
    /// touch its ends. The domain edge of a boundary star goes through the centre and is
    /// computed in full.
    fn ring_edge_error(&self, i: usize) -> SegmentError {
        let m = self.ring.len();
        let stars = self.star_bounds.len();
        if i >= stars {
            return self.segment_error(i, (i + 1) % m);
        }
        let mut bound = self.star_bounds[i];
        for j in [(i + m - 1) % m, (i + 1) % m] {
            if j < stars {
                bound.above = bound.above.max(self.star_bounds[j].above);
                bound.below = bound.below.max(self.star_bounds[j].below);
            }
        }
        SegmentError {
            bound,
            introduced: 0.0,
        }
    }
}

/// Whether closed segments `ab` and `cd` share a point. Exact.
#[cfg(test)]
fn segments_meet(a: &Point, b: &Point, c: &Point, d: &Point) -> bool {
    let (d1, d2) = (orient(a, b, c), orient(a, b, d));
    let (d3, d4) = (orient(c, d, a), orient(c, d, b));
    if ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)) {
        return true;
    }
    let on = |p: &Point, q: &Point, r: &Point| {
        orient(p, q, r) == 0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
}

/// Whether `b` lies strictly inside the interior angle at polygon vertex `a` (with
/// neighbours `prev` and `next`, counter-clockwise polygon). Exact.
#[cfg(test)]
fn in_cone(prev: &Point, a: &Point, next: &Point, b: &Point) -> bool {
    if orient(prev, a, next) >= 0 {
        // Convex (or straight) corner.
        orient(a, next, b) > 0 && orient(a, b, prev) > 0
    } else {
        !(orient(a, next, b) <= 0 && orient(a, b, prev) <= 0)
    }
}

/// Squared length of the segment `pq` in sample spacings.
pub(crate) fn squared_length(p: &Point, q: &Point) -> i64 {
    let (dx, dy) = (p.x - q.x, p.y - q.y);
    dx * dx + dy * dy
}

fn within(bound: ErrorBound, limit: f64) -> bool {
    bound.above <= limit && bound.below <= limit
}

/// The parameter interval `[t_lo, t_hi]` of segment `p + t (q - p)`, `t ∈ [0, 1]`, inside
/// the closed counter-clockwise triangle `tri`, or `None` when they do not meet. Whether
/// they meet is decided exactly; the interval ends are then rounded to `f64`.
fn clip_segment(p: &Point, q: &Point, tri: &[Point; 3]) -> Option<(f64, f64)> {
    // Rationals num/den with den > 0; numerators and denominators are differences of
    // orientations (below 2^34), their cross products are compared in i128.
    let (mut lo_n, mut lo_d) = (0i64, 1i64);
    let (mut hi_n, mut hi_d) = (1i64, 1i64);
    let less = |n1: i64, d1: i64, n2: i64, d2: i64| {
        (n1 as i128) * (d2 as i128) < (n2 as i128) * (d1 as i128)
    };
    for k in 0..3 {
        let (a, b) = (&tri[k], &tri[(k + 1) % 3]);
        let f0 = orient(a, b, p);
        let f1 = orient(a, b, q);
        match (f0 >= 0, f1 >= 0) {
            (true, true) => {}
            (false, false) => return None,
            (true, false) => {
                // t <= f0 / (f0 - f1)
                let (n, d) = (f0, f0 - f1);
                if less(n, d, hi_n, hi_d) {
                    (hi_n, hi_d) = (n, d);
                }
            }
            (false, true) => {
                // t >= -f0 / (f1 - f0)
                let (n, d) = (-f0, f1 - f0);
                if less(lo_n, lo_d, n, d) {
                    (lo_n, lo_d) = (n, d);
                }
            }
        }
    }
    if less(hi_n, hi_d, lo_n, lo_d) {
        return None;
    }
    Some((lo_n as f64 / lo_d as f64, hi_n as f64 / hi_d as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

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
            max_edge_squared: i64::MAX,
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
