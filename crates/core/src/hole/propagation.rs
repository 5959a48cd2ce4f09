//! The paper's error propagation (§3.3): bounds of the new triangles from the bounds of the
//! star triangles they overlap.
//!
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

use super::{Retriangulator, SegmentError, VariableLayer};
use crate::predicates::{in_closed_triangle, orient, plane_gradient, Point};
use crate::ErrorBound;

impl Retriangulator {
    /// The star triangles' gradients and an empty table of segment errors, for the error
    /// propagation of §3.3 and the ears' introduced error.
    pub(super) fn prepare_segments(&mut self) {
        let centre = self.centre.expect("hole loaded");
        let m = self.ring.len();
        self.segments.clear();
        self.segments.resize(m * m, None);
        self.star_gradients.clear();
        for i in 0..self.star_bounds.len() {
            let g = plane_gradient(&centre, &self.ring[i], &self.ring[(i + 1) % m]);
            self.star_gradients.push(g);
        }
        let stars = self.star_bounds.len();
        for layer in &mut self.variable_layers[..self.variable_count] {
            layer.gradients.clear();
            for i in 0..stars {
                let g = plane_gradient(&layer.centre, &layer.ring[i], &layer.ring[(i + 1) % m]);
                layer.gradients.push(g);
            }
        }
    }

    /// Loads the values of `grid`'s variables on the loaded hole (the ring's and the
    /// centre's samples), for the bounds model with several variables: each new triangle's
    /// bound then covers every variable's propagated error too, scaled into height units
    /// (see [`crate::variables`]). [`Retriangulator::load`] forgets them.
    pub(crate) fn load_variables(&mut self, grid: &crate::Grid) {
        let centre = self.centre.expect("hole loaded");
        let width = i64::from(grid.width());
        self.variable_count = 0;
        for v in grid.variables() {
            let Some(scale) = v.propagation_scale() else {
                continue;
            };
            if self.variable_layers.len() == self.variable_count {
                self.variable_layers.push(VariableLayer::default());
            }
            let layer = &mut self.variable_layers[self.variable_count];
            let values = v.grid.values();
            let at = |p: &Point| Point {
                z: values[(p.y * width + p.x) as usize],
                ..*p
            };
            layer.ring.clear();
            layer.ring.extend(self.ring.iter().map(at));
            layer.centre = Point {
                z: values[(centre.y * width + centre.x) as usize],
                ..centre
            };
            layer.scale = scale;
            self.variable_count += 1;
        }
    }

    /// The cached error of the segment between ring vertices `i < j` (a ring edge or a
    /// diagonal).
    pub(super) fn segment(&mut self, i: usize, j: usize) -> SegmentError {
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

    /// Bound of new triangle `abc` from its edges' bounds and, when the removed vertex lies
    /// in it, from the removed vertex's own error against every star triangle.
    pub(super) fn triangle_bound(
        &self,
        a: usize,
        b: usize,
        c: usize,
        edges: [SegmentError; 3],
    ) -> ErrorBound {
        let mut bound = edges[0].bound;
        for e in &edges[1..] {
            bound.above = bound.above.max(e.bound.above);
            bound.below = bound.below.max(e.bound.below);
        }
        let centre = self.centre.expect("hole loaded");
        let (pa, pb, pc) = (&self.ring[a], &self.ring[b], &self.ring[c]);
        if in_closed_triangle(pa, pb, pc, &centre) {
            let layers = std::iter::once((&self.ring[..], &centre, 1.0)).chain(
                self.variable_layers[..self.variable_count]
                    .iter()
                    .map(|l| (&l.ring[..], &l.centre, l.scale)),
            );
            for (ring, centre, scale) in layers {
                let (pa, pb, pc) = (&ring[a], &ring[b], &ring[c]);
                let g = plane_gradient(pa, pb, pc);
                let new_at_centre =
                    pa.z + g[0] * (centre.x - pa.x) as f64 + g[1] * (centre.y - pa.y) as f64;
                let delta = scaled(new_at_centre - centre.z, scale);
                bound.above = bound.above.max(self.max_star_above - delta);
                bound.below = bound.below.max(self.max_star_below + delta);
            }
        }
        bound
    }

    /// Error of the segment from ring vertex `from` to ring vertex `to`: for each closed
    /// star triangle it meets, the signed introduced error at its entry and exit points
    /// folded into that triangle's bound (paper §3.3.1). With variables loaded (bounds
    /// model), each variable's scaled introduced error is folded in too: a star triangle's
    /// bound covers every variable's scaled error, so the largest of the folds covers them
    /// on the new segment. The introduced error reported is the height's.
    fn segment_error(&self, from: usize, to: usize) -> SegmentError {
        let mut out = SegmentError {
            bound: ErrorBound {
                above: f64::NEG_INFINITY,
                below: f64::NEG_INFINITY,
            },
            introduced: 0.0,
        };
        let centre = self.centre.expect("hole loaded");
        self.fold_segment(
            Layer {
                ring: &self.ring,
                centre: &centre,
                gradients: &self.star_gradients,
                scale: 1.0,
            },
            from,
            to,
            &mut out,
        );
        let introduced = out.introduced;
        for l in &self.variable_layers[..self.variable_count] {
            let layer = Layer {
                ring: &l.ring,
                centre: &l.centre,
                gradients: &l.gradients,
                scale: l.scale,
            };
            self.fold_segment(layer, from, to, &mut out);
        }
        out.introduced = introduced;
        // Finite unless a star triangle's own bound is not (a triangle a variable keeps
        // beyond its limit, see `crate::variables::with_variables`), or a variable held at
        // a bound of 0 changes along the segment.
        debug_assert!(
            out.bound.above.is_finite()
                || self.variable_count > 0
                || self.star_bounds.iter().any(|b| !b.above.is_finite()),
            "a ring segment meets its star"
        );
        out
    }

    /// [`Retriangulator::segment_error`]'s folds for one layer of values (the heights, or
    /// a variable's values scaled by `layer.scale`) into `out`.
    fn fold_segment(&self, layer: Layer<'_>, from: usize, to: usize, out: &mut SegmentError) {
        let Layer {
            ring,
            centre,
            gradients,
            scale,
        } = layer;
        let centre = *centre;
        let (p, q) = (ring[from], ring[to]);
        let m = ring.len();
        let stars = self.star_bounds.len();
        // A diagonal of the (star-shaped) hole splits it in two; it crosses the spokes of
        // the chain on the far side from the centre and touches the two star triangles
        // beyond its ends at a shared corner. Walking it with the centre on its left, the
        // introduced error is linear between consecutive spoke crossings, so each crossed
        // triangle's extremes are at the crossings on its two spokes.
        let side = orient(&p, &q, &centre);
        if side != 0 {
            let (a, b) = if side > 0 { (from, to) } else { (to, from) };
            let (p, q) = (ring[a], ring[b]);
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
            fold((a + m - 1) % m, 0.0, 0.0, out);
            for step in 1..=span {
                let k = (a + step) % m;
                let current = if step == span {
                    0.0
                } else {
                    let r = &ring[k];
                    let (fp, fq) = (orient(&centre, r, &p) as f64, orient(&centre, r, &q) as f64);
                    let t = fp / (fp - fq);
                    let u = side / (side - orient(&p, &q, r) as f64);
                    let new = p.z + t * (q.z - p.z);
                    let old = centre.z + u * (r.z - centre.z);
                    scaled(new - old, scale)
                };
                let i = (k + m - 1) % m;
                fold(i, previous.min(current), previous.max(current), out);
                out.introduced = out.introduced.max(current.abs());
                previous = current;
            }
            fold(b, 0.0, 0.0, out);
            return;
        }
        // The centre is on the segment: it touches every star triangle there.
        for i in 0..m.min(stars) {
            let (star_bound, g) = (&self.star_bounds[i], &gradients[i]);
            let tri = [centre, ring[i], ring[(i + 1) % m]];
            let Some((t_lo, t_hi)) = clip_segment(&p, &q, &tri) else {
                continue;
            };
            let delta = |t: f64| {
                let sx = p.x as f64 + t * (q.x - p.x) as f64;
                let sy = p.y as f64 + t * (q.y - p.y) as f64;
                let new = p.z + t * (q.z - p.z);
                let old = centre.z + g[0] * (sx - centre.x as f64) + g[1] * (sy - centre.y as f64);
                scaled(new - old, scale)
            };
            let (d0, d1) = (delta(t_lo), delta(t_hi));
            let (lo, hi) = (d0.min(d1), d0.max(d1));
            out.bound.above = out.bound.above.max(star_bound.above - lo);
            out.bound.below = out.bound.below.max(star_bound.below + hi);
            out.introduced = out.introduced.max(lo.abs()).max(hi.abs());
        }
    }

    /// Error of ring edge `i` (from ring vertex `i` to the next): the surface does not
    /// change along it, so it carries the bounds of the star triangles that contain it or
    /// touch its ends. The domain edge of a boundary star goes through the centre and is
    /// computed in full.
    pub(super) fn ring_edge_error(&self, i: usize) -> SegmentError {
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

/// The parameter interval `[t_lo, t_hi]` of segment `p + t (q - p)`, `t ∈ [0, 1]`, inside
/// the closed counter-clockwise triangle `tri`, or `None` when they do not meet. Whether
/// they meet is decided exactly; the interval ends are then rounded to `f64`.
pub(super) fn clip_segment(p: &Point, q: &Point, tri: &[Point; 3]) -> Option<(f64, f64)> {
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

/// One layer of values on the hole's geometry for [`Retriangulator::fold_segment`]: the
/// ring and centre with those values as `z`, the star triangles' gradients of them, and
/// the factor that takes their differences into height units.
#[derive(Clone, Copy)]
struct Layer<'a> {
    ring: &'a [Point],
    centre: &'a Point,
    gradients: &'a [[f64; 2]],
    scale: f64,
}

/// `delta` in height units: times `scale`, with 0 kept 0 when the scale is infinite (a
/// variable held at a bound of 0: any change is infinitely large, no change is none).
fn scaled(delta: f64, scale: f64) -> f64 {
    if scale == 1.0 || delta == 0.0 {
        delta
    } else {
        delta * scale
    }
}
