//! The hole's triangulation of least maximum error (then, with contour levels, fewest
//! levels spanned and least Dirichlet energy) by dynamic programming over the ring,
//! solved top-down.

use super::{HoleTriangle, Retriangulator, Rules, SegmentError};
use crate::coverage::Coverage;
use crate::levels::{dirichlet_energy, triangle_levels};
use crate::predicates::orient;
#[cfg(test)]
use crate::predicates::Point;
use crate::ErrorModel;

/// How much the top-down DP knows about an interval's optimum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Solved {
    /// Not yet asked.
    Unknown,
    /// `cost`, `cost_sum` and `split` hold the optimum (`split == u32::MAX`: no
    /// triangulation within the limit).
    Exact,
    /// The optimum's largest error exceeds the value in `cost`.
    Above,
}

impl Retriangulator {
    /// Min-max-error triangulation of the hole by dynamic programming over ring intervals:
    /// `cost(i, j) = min over k of max(cost(i, k), cost(k, j), error(i, k, j))`, optimal for
    /// the error model (with levels: the fewest levels spanned among triangulations within
    /// the limit). Ties within an interval go to the smallest summed error (least Dirichlet
    /// energy), then the smallest `k`. Solved top-down from the whole ring (see
    /// [`Retriangulator::solve_interval`]).
    pub(super) fn dynamic_programming<S: Coverage + ?Sized>(
        &mut self,
        rules: &Rules<'_, S>,
    ) -> bool {
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
    fn solve_interval<S: Coverage + ?Sized>(
        &mut self,
        i: usize,
        j: usize,
        cap: f64,
        rules: &Rules<'_, S>,
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

    /// Whether the segment between ring vertices `i` and `j` (not neighbours) is a diagonal
    /// of the hole polygon: inside it and touching its boundary only at its ends. Exact.
    pub(super) fn is_diagonal(&self, i: usize, j: usize) -> bool {
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
    pub(super) fn is_diagonal_general(&self, i: usize, j: usize) -> bool {
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
