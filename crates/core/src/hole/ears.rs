//! The paper's ear selection (§3.4): the hole is filled by cutting off ears one at a time,
//! the ear chosen by the edge selection rule.

use super::{HoleTriangle, Retriangulator, Rules, SegmentError};
use crate::coverage::Coverage;
use crate::predicates::{in_closed_triangle, orient};
use crate::{EdgeSelection, ErrorBound, ErrorModel};

/// An ear at ring vertex `q`, cutting off `(prev q, q, next q)`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ear {
    diagonal: SegmentError,
    triangle: ErrorBound,
}

impl Retriangulator {
    pub(super) fn clip_ears<S: Coverage + ?Sized>(
        &mut self,
        rule: EdgeSelection,
        rules: &Rules<'_, S>,
    ) -> bool {
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
    fn ear<S: Coverage + ?Sized>(&mut self, q: usize, rules: &Rules<'_, S>) -> Option<Ear> {
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
}
