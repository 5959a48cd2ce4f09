//! A coarse initial mesh: a right-triangulated irregular network (RTIN, the longest-edge
//! bisection hierarchy of a power-of-two square) refined only where a triangle's exact
//! error exceeds the limit or it would cover a nodata cell (beyond the paper).
//!
//! Vertex removal from the full grid costs time per sample even where the surface is
//! smooth. Starting from the coarsest RTIN whose every triangle is within the limit skips
//! most of those removals; decimation then continues from it as from the full grid.
//!
//! # Conformity
//! Each sample inside the top square is the hypotenuse midpoint of exactly one *diamond*
//! (the one or two triangles sharing that hypotenuse). Both triangles of a diamond split
//! together, and a triangle exists only if the diamond it comes from is split; then the
//! emitted triangles meet edge to edge (no T-junctions). Two ways to get there:
//!
//! - *Bottom-up* ([`Rtin::saturate`]): level by level from the finest, a diamond splits
//!   when either of its triangles must split or when any of its children's diamonds is
//!   split: the error saturation of RTIN terrain meshes (e.g. Mapbox's martini), here with
//!   an exact error. A failing fine triangle settles all its ancestors without measuring
//!   them, so this is cheap where most samples stay (small bounds, rough data), but every
//!   fine triangle is measured even where the surface is smooth.
//! - *Top-down* ([`Rtin::refine`]): from the two top triangles, a triangle splits when it
//!   must, and splitting a diamond first splits the diamonds its triangles come from (the
//!   forced splits of ROAM). Smooth regions stop at their largest fitting triangle, so this
//!   is cheap where few samples stay (large bounds), and measures one large failing
//!   triangle per split where most stay.
//!
//! [`rtin_triangles`] picks one per grid from a sparse probe of the finest level (the
//! fraction of 2x2 squares that cannot be two triangles): bottom-up above
//! [`TOP_DOWN_BELOW`], top-down below. Both give a conforming mesh whose every triangle was
//! measured within the limit; their meshes differ slightly (top-down keeps a triangle that
//! fits even when one of its descendants would not).
//!
//! # Guarantees
//! Every emitted triangle lies in the domain (all cells in its bounding box are valid) and
//! its exact error is within the limit; every valid cell is covered; every sample where
//! the domain's outline turns or pinches is a vertex (a sample inside an emitted edge has
//! all four cells around it valid, or lies on a straight stretch of the grid's border).

use crate::exact::triangle_error;
use crate::mesh::CompactBound;
use crate::predicates::{orient, Point};
use crate::{EdgeLimit, Grid};

type Xy = (i64, i64);

/// Triangles (counter-clockwise sample indices) of the coarsest conforming RTIN over the
/// grid's domain whose triangles all have exact error at most `limit`, with those errors.
///
/// Triangles with an edge beyond `edge_limit` split too.
/// With `full_border`, every triangle that reaches the grid's outer rows or columns is a
/// half cell, so the strip of cells along the border is triangulated as in the full grid
/// (what [`crate::decimate_with_border`] needs to remove border samples inside the strip).
pub(crate) fn rtin_triangles(
    grid: &Grid,
    limit: f64,
    edge_limit: &EdgeLimit,
    full_border: bool,
) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
    let rtin = Rtin::new(grid, limit, edge_limit, full_border);
    let need = rtin.refinement();
    rtin.triangles(&need)
}

/// The RTIN of [`rtin_triangles`], if its probe finds it cheap to build (it refines
/// top-down: few of the finest squares split, so it stops at large triangles) and it has
/// fewer than `fewer_than` triangles; `None` otherwise, without emitting any.
pub(crate) fn cheap_rtin_with_fewer_triangles(
    grid: &Grid,
    limit: f64,
    edge_limit: &EdgeLimit,
    full_border: bool,
    fewer_than: usize,
) -> Option<(Vec<[u32; 3]>, Vec<CompactBound>)> {
    let rtin = Rtin::new(grid, limit, edge_limit, full_border);
    if rtin.finest_split_fraction() > TOP_DOWN_BELOW {
        return None;
    }
    let need = rtin.refine();
    (rtin.count(&need) < fewer_than).then(|| rtin.triangles(&need))
}

/// The start for a count target: of the RTINs at bounds `range / 2^k`, k = 1, 2, ...
/// (`range` the spread of the grid's values) that are within `limit`, the first with at
/// least `triangles` triangles more than the RTIN at no bound has, or the last tried if
/// none has (a nearly planar grid).
/// Greedy removal then decimates to the count from there: from the RTIN at no bound at
/// all it would start below the count, and from the full grid it would spend its time on
/// removals the RTIN makes for free. The bounds tried do not depend on `limit` beyond
/// skipping those above it, so a rerun within the bound a count target reported starts
/// from the same mesh.
pub(crate) fn rtin_for_count(
    grid: &Grid,
    triangles: usize,
    limit: f64,
    edge_limit: &EdgeLimit,
    full_border: bool,
    tick: &dyn Fn(),
) -> (Vec<[u32; 3]>, Vec<CompactBound>, f64) {
    let (lo, hi) = grid
        .values()
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let range = if hi > lo { hi - lo } else { 1.0 };
    // Triangles the domain's shape forces whatever the bound (splits along nodata and
    // the edges of a grid that is not a power-of-two square) do not count towards the
    // start's room: on ETOPO5 they are 7,392.
    let forced = {
        let rtin = Rtin::new(grid, f64::INFINITY, edge_limit, full_border);
        rtin.count(&rtin.refinement())
    };
    let triangles = triangles.saturating_add(forced);
    let mut bound = range / 2.0;
    // 2^-40 of the range is far below any meaningful error, and the RTIN there is close
    // to the full grid.
    for _ in 0..40 {
        tick();
        if bound <= limit {
            let rtin = Rtin::new(grid, bound, edge_limit, full_border);
            let need = rtin.refinement();
            if rtin.count(&need) >= triangles {
                let (c, b) = rtin.triangles(&need);
                return (c, b, bound);
            }
        }
        bound /= 2.0;
    }
    let (c, b) = rtin_triangles(grid, bound.min(limit), edge_limit, full_border);
    (c, b, bound.min(limit))
}

/// The probed fraction of finest squares that split, below which [`rtin_triangles`] refines
/// top-down. Measured (one thread, Big Tujunga, a 2048² ETOPO5 resample and a
/// CT slice at bounds 0.5 to 30): top-down took 0.4-0.8 x bottom-up's time where the probe
/// gave 0-0.24, the same at 0.27, and 1.06-1.5 x at 0.49-1.
const TOP_DOWN_BELOW: f64 = 0.3;

/// One probe per this many finest squares along each axis.
const PROBE_STRIDE: i64 = 4;

struct Rtin<'g> {
    grid: &'g Grid,
    limit: f64,
    /// Last sample column and row.
    max_x: i64,
    max_y: i64,
    /// Side of the top square: the smallest power of two covering the grid.
    size: i64,
    /// Invalid cells counted over `[0, x) x [0, y)` (summed-area table over cells), when
    /// the grid has any.
    invalid: Option<Vec<u32>>,
    /// Whether triangles reaching the outer rows or columns always split (to half cells).
    full_border: bool,
    /// Triangles with an edge beyond it always split.
    edge_limit: &'g EdgeLimit,
}

impl<'g> Rtin<'g> {
    fn new(grid: &'g Grid, limit: f64, edge_limit: &'g EdgeLimit, full_border: bool) -> Rtin<'g> {
        let (w, h) = (grid.width() as i64, grid.height() as i64);
        let mut size = 1;
        while size < (w - 1).max(h - 1) {
            size *= 2;
        }
        let invalid = (grid.valid_cell_count() as i64 != (w - 1) * (h - 1)).then(|| {
            let (cw, ch) = ((w - 1) as usize, (h - 1) as usize);
            let mut sat = vec![0u32; (cw + 1) * (ch + 1)];
            for y in 0..ch {
                let mut row = 0;
                for x in 0..cw {
                    row += u32::from(!grid.cell_is_valid(x, y));
                    sat[(y + 1) * (cw + 1) + x + 1] = sat[y * (cw + 1) + x + 1] + row;
                }
            }
            sat
        });
        Rtin {
            grid,
            limit,
            max_x: w - 1,
            max_y: h - 1,
            size,
            invalid,
            full_border,
            edge_limit,
        }
    }

    fn inside(&self, p: Xy) -> bool {
        p.0 >= 0 && p.1 >= 0 && p.0 <= self.max_x && p.1 <= self.max_y
    }

    fn index(&self, p: Xy) -> usize {
        (p.1 * (self.max_x + 1) + p.0) as usize
    }

    /// Where triangle `abc` lies relative to the grid.
    fn extent(&self, t: [Xy; 3]) -> Extent {
        let (x0, x1, y0, y1) = bbox(t);
        if x0 >= self.max_x || y0 >= self.max_y || x1 <= 0 || y1 <= 0 {
            Extent::Outside
        } else if x0 < 0 || y0 < 0 || x1 > self.max_x || y1 > self.max_y {
            Extent::Partly
        } else {
            Extent::Inside
        }
    }

    /// Whether a triangle inside the grid (and larger than a half cell) must be split: it
    /// may cover an invalid cell (its bounding box holds one), it reaches the outer border
    /// in full-border mode, an edge is too long or it is turned over on the globe
    /// ([`EdgeLimit::faces_out`]), or its exact error exceeds the limit.
    fn must_split(&self, t: [Xy; 3]) -> bool {
        let (x0, x1, y0, y1) = bbox(t);
        if self.full_border && (x0 == 0 || y0 == 0 || x1 == self.max_x || y1 == self.max_y) {
            return true;
        }
        // On the grid the hypotenuse (between t[0] and t[1]) is the longest edge; on a
        // sphere the legs are measured too.
        if !self.edge_limit.is_none() || self.edge_limit.on_sphere() {
            let p = |k: usize| Point {
                x: t[k].0,
                y: t[k].1,
                z: 0.0,
            };
            if [(0, 1), (1, 2), (2, 0)]
                .iter()
                .any(|&(i, j)| !self.edge_limit.allows(&p(i), &p(j)))
            {
                return true;
            }
            let [a, b, c] = [p(0), p(1), p(2)];
            let faces_out = if orient(&a, &b, &c) > 0 {
                self.edge_limit.faces_out(&a, &b, &c)
            } else {
                self.edge_limit.faces_out(&a, &c, &b)
            };
            if !faces_out {
                return true;
            }
        }
        if let Some(sat) = &self.invalid {
            let cw = self.max_x as usize + 1;
            let at = |x: i64, y: i64| sat[y as usize * cw + x as usize];
            if at(x1, y1) + at(x0, y0) - at(x0, y1) - at(x1, y0) > 0 {
                return true;
            }
        }
        let [a, b, c] = self.points(t);
        let (b, c) = if orient(&a, &b, &c) > 0 {
            (b, c)
        } else {
            (c, b)
        };
        triangle_error(self.grid, &a, &b, &c, self.limit).is_none()
    }

    fn points(&self, t: [Xy; 3]) -> [Point; 3] {
        t.map(|p| Point {
            x: p.0,
            y: p.1,
            z: self.grid.vertex_height(self.index(p)),
        })
    }

    /// Whether the diamond with hypotenuse midpoint `m` is split; samples outside the grid
    /// stand for diamonds that reach outside and always split.
    fn split(&self, need: &[bool], m: Xy) -> bool {
        !self.inside(m) || need[self.index(m)]
    }

    /// Bottom-up saturation: `need[m]` says whether the diamond at `m` splits.
    fn saturate(&self) -> Vec<bool> {
        let mut need = vec![false; ((self.max_x + 1) * (self.max_y + 1)) as usize];
        let mut s = 2;
        while s <= self.size {
            let h = s / 2;
            // Diamonds whose hypotenuse is a side of an s-square (midpoint on the side):
            // the two quarter triangles on either side, right angle at a square centre.
            for horizontal in [true, false] {
                let (mut i, mut j) = (0, 0);
                loop {
                    let m = if horizontal {
                        (i * s + h, j * s)
                    } else {
                        (i * s, j * s + h)
                    };
                    if m.1 > self.max_y {
                        break;
                    }
                    if m.0 > self.max_x {
                        (i, j) = (0, j + 1);
                        continue;
                    }
                    let (a, b) = if horizontal {
                        ((m.0 - h, m.1), (m.0 + h, m.1))
                    } else {
                        ((m.0, m.1 - h), (m.0, m.1 + h))
                    };
                    let centres = if horizontal {
                        [(m.0, m.1 - h), (m.0, m.1 + h)]
                    } else {
                        [(m.0 - h, m.1), (m.0 + h, m.1)]
                    };
                    let mut split = false;
                    for c in centres {
                        let t = [a, b, c];
                        split |= match self.extent(t) {
                            Extent::Outside => false,
                            Extent::Partly => true,
                            Extent::Inside => {
                                (s > 2
                                    && (self.split(&need, mid(c, a))
                                        || self.split(&need, mid(b, c))))
                                    || self.must_split(t)
                            }
                        };
                        if split {
                            break;
                        }
                    }
                    need[self.index(m)] = split;
                    i += 1;
                }
            }
            // Diamonds whose hypotenuse is an s-square's diagonal (midpoint at its centre).
            let mut j = 0;
            while j * s + h <= self.max_y {
                let mut i = 0;
                while i * s + h <= self.max_x {
                    let (x, y) = (i * s, j * s);
                    let c = (x + h, y + h);
                    let corners = [(x, y), (x + s, y), (x + s, y + s), (x, y + s)];
                    let mut split = x + s > self.max_x || y + s > self.max_y;
                    for k in 0..4 {
                        split = split || self.split(&need, mid(corners[k], corners[(k + 1) % 4]));
                    }
                    if !split {
                        let halves = if (i + j) % 2 == 0 {
                            [
                                [corners[0], corners[2], corners[1]],
                                [corners[2], corners[0], corners[3]],
                            ]
                        } else {
                            [
                                [corners[1], corners[3], corners[2]],
                                [corners[3], corners[1], corners[0]],
                            ]
                        };
                        split = halves.iter().any(|&t| self.must_split(t));
                    }
                    need[self.index(c)] = split;
                    i += 1;
                }
                j += 1;
            }
            s *= 2;
        }
        need
    }

    /// The split diamonds, by whichever refinement the probe picks (see the module docs).
    fn refinement(&self) -> Vec<bool> {
        if self.finest_split_fraction() > TOP_DOWN_BELOW {
            self.saturate()
        } else {
            self.refine()
        }
    }

    /// How many triangles [`Rtin::triangles`] would give.
    fn count(&self, need: &[bool]) -> usize {
        let s = self.size;
        let mut count = 0;
        for (a, b, c) in [((0, 0), (s, s), (s, 0)), ((s, s), (0, 0), (0, s))] {
            self.emit(a, b, c, need, &mut |_| count += 1);
        }
        count
    }

    /// The triangles (counter-clockwise sample indices) of the refinement `need`, with
    /// their exact errors.
    fn triangles(&self, need: &[bool]) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
        let s = self.size;
        // Counted first so that the arrays are allocated once, at their size: at small
        // bounds they hold nearly two triangles per sample, and doubling growth would
        // waste up to half.
        let count = self.count(need);
        let mut out = (Vec::with_capacity(count), Vec::with_capacity(count));
        for (a, b, c) in [((0, 0), (s, s), (s, 0)), ((s, s), (0, 0), (0, s))] {
            self.emit(a, b, c, need, &mut |t| self.push(t, &mut out));
        }
        out
    }

    /// The fraction of a sparse, fixed sample of 2x2 squares (one in [`PROBE_STRIDE`]²)
    /// whose two triangles, split along the finest diagonal diamonds' hypotenuse, cannot
    /// both stay; 1 when the grid has no such square.
    fn finest_split_fraction(&self) -> f64 {
        let (mut probed, mut split) = (0u32, 0u32);
        let step = 2 * PROBE_STRIDE;
        let mut y = 0;
        while y + 2 <= self.max_y {
            let mut x = 0;
            while x + 2 <= self.max_x {
                let [c0, c1, c2, c3] = [(x, y), (x + 2, y), (x + 2, y + 2), (x, y + 2)];
                probed += 1;
                if self.must_split([c0, c2, c1]) || self.must_split([c2, c0, c3]) {
                    split += 1;
                }
                x += step;
            }
            y += step;
        }
        if probed == 0 {
            1.0
        } else {
            f64::from(split) / f64::from(probed)
        }
    }

    /// Top-down refinement: `need[m]` says whether the diamond at `m` splits. A triangle
    /// splits when it reaches outside the grid or must (see [`Rtin::must_split`]); see
    /// [`Rtin::split_diamond`] for conformity. Every triangle left whole that lies inside
    /// the grid was measured within the limit.
    fn refine(&self) -> Vec<bool> {
        let mut need = vec![false; ((self.max_x + 1) * (self.max_y + 1)) as usize];
        // Split diamonds whose midpoint is outside the grid (`split` treats them as split).
        let mut outside = std::collections::HashSet::new();
        let s = self.size;
        let mut queue = vec![[(0, 0), (s, s), (s, 0)], [(s, s), (0, 0), (0, s)]];
        while let Some(t) = queue.pop() {
            let [a, b, _] = t;
            if (a.0 - b.0).abs() == 1 {
                continue; // a half cell
            }
            let m = mid(a, b);
            let split = match self.extent(t) {
                Extent::Outside => false,
                Extent::Partly => true,
                // A split diamond's children are already queued.
                Extent::Inside => !need[self.index(m)] && self.must_split(t),
            };
            if split {
                self.split_diamond(m, &mut need, &mut outside, &mut queue);
            }
        }
        need
    }

    /// Splits the diamond at `m` unless it is already, after splitting the diamonds its
    /// triangles come from (a triangle's parent diamond has its midpoint at the triangle's
    /// right-angle corner; the two top triangles have none), and queues the children of
    /// its triangles.
    fn split_diamond(
        &self,
        m: Xy,
        need: &mut [bool],
        outside: &mut std::collections::HashSet<Xy>,
        queue: &mut Vec<[Xy; 3]>,
    ) {
        if self.inside(m) {
            let i = self.index(m);
            if need[i] {
                return;
            }
            need[i] = true;
        } else if !outside.insert(m) {
            return;
        }
        let (p, q) = self.hypotenuse(m);
        let half = ((q.0 - p.0) / 2, (q.1 - p.1) / 2);
        for sign in [1, -1] {
            let apex = (m.0 - sign * half.1, m.1 + sign * half.0);
            let in_top_square =
                (0..=self.size).contains(&apex.0) && (0..=self.size).contains(&apex.1);
            if !in_top_square || self.extent([p, q, apex]) == Extent::Outside {
                continue;
            }
            let top_corner =
                (apex.0 == 0 || apex.0 == self.size) && (apex.1 == 0 || apex.1 == self.size);
            if !top_corner {
                self.split_diamond(apex, need, outside, queue);
            }
            queue.push([apex, p, m]);
            queue.push([q, apex, m]);
        }
    }

    /// The hypotenuse of the diamond whose midpoint is `m` (inside the top square, not one
    /// of its corners), as [`Rtin::saturate`] lays the diamonds out: with `k` the largest
    /// power of two dividing both coordinates, a midpoint with one coordinate an odd
    /// multiple of `k` is on a side of a `2k`-square, with both, at its centre (the
    /// diagonal alternating with the square's parity).
    fn hypotenuse(&self, m: Xy) -> (Xy, Xy) {
        let zeros = |v: i64| if v == 0 { 63 } else { v.trailing_zeros() };
        let z = zeros(m.0).min(zeros(m.1));
        let k = 1i64 << z;
        match ((m.0 >> z) & 1 == 1, (m.1 >> z) & 1 == 1) {
            (true, true) => {
                let (i, j) = ((m.0 - k) / (2 * k), (m.1 - k) / (2 * k));
                if (i + j) % 2 == 0 {
                    ((m.0 - k, m.1 - k), (m.0 + k, m.1 + k))
                } else {
                    ((m.0 + k, m.1 - k), (m.0 - k, m.1 + k))
                }
            }
            (true, false) => ((m.0 - k, m.1), (m.0 + k, m.1)),
            _ => ((m.0, m.1 - k), (m.0, m.1 + k)),
        }
    }

    /// Passes triangle `(a, b, c)` (hypotenuse `ab`, right angle at `c`) or its children
    /// to `out`, in a fixed order.
    fn emit(&self, a: Xy, b: Xy, c: Xy, need: &[bool], out: &mut dyn FnMut([Xy; 3])) {
        let t = [a, b, c];
        let extent = self.extent(t);
        if extent == Extent::Outside {
            return;
        }
        let leaf = (a.0 - b.0).abs() == 1;
        if leaf {
            let (x, y) = (a.0.min(b.0), a.1.min(b.1));
            if extent == Extent::Inside && self.grid.cell_is_valid(x as usize, y as usize) {
                out(t);
            }
            return;
        }
        let m = mid(a, b);
        if extent == Extent::Partly || need[self.index(m)] {
            self.emit(c, a, m, need, out);
            self.emit(b, c, m, need, out);
        } else {
            out(t);
        }
    }

    fn push(&self, t: [Xy; 3], out: &mut (Vec<[u32; 3]>, Vec<CompactBound>)) {
        let [a, b, c] = self.points(t);
        let (b, c, tb, tc) = if orient(&a, &b, &c) > 0 {
            (b, c, t[1], t[2])
        } else {
            (c, b, t[2], t[1])
        };
        let bound = triangle_error(self.grid, &a, &b, &c, f64::INFINITY).expect("no limit");
        out.0.push([t[0], tb, tc].map(|p| self.index(p) as u32));
        out.1.push(bound.into());
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Extent {
    Inside,
    Partly,
    Outside,
}

/// `(x_min, x_max, y_min, y_max)` of a triangle.
fn bbox(t: [Xy; 3]) -> (i64, i64, i64, i64) {
    let xs = [t[0].0, t[1].0, t[2].0];
    let ys = [t[0].1, t[1].1, t[2].1];
    (
        xs.into_iter().min().unwrap_or(0),
        xs.into_iter().max().unwrap_or(0),
        ys.into_iter().min().unwrap_or(0),
        ys.into_iter().max().unwrap_or(0),
    )
}

fn mid(a: Xy, b: Xy) -> Xy {
    ((a.0 + b.0) / 2, (a.1 + b.1) / 2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edge_limit::NO_EDGE_LIMIT;
    use crate::EdgeMetric;
    use std::collections::{HashMap, HashSet};
    use tinsmith_testkit::{terrain, with_nodata_disc, GridSpec};

    fn grid(spec: GridSpec) -> Grid {
        Grid::new(spec.width, spec.height, spec.values).unwrap()
    }

    fn triangles(rtin: &Rtin<'_>, need: &[bool]) -> Vec<[Xy; 3]> {
        let s = rtin.size;
        let mut out = Vec::new();
        for (a, b, c) in [((0, 0), (s, s), (s, 0)), ((s, s), (0, 0), (0, s))] {
            rtin.emit(a, b, c, need, &mut |t| out.push(t));
        }
        out
    }

    /// Every triangle is within the limit; no vertex lies inside another triangle's edge
    /// (no T-junctions) and no edge has more than two triangles; the triangles cover
    /// exactly the valid cells' area. Returns the triangle count.
    fn check_mesh(grid: &Grid, rtin: &Rtin<'_>, need: &[bool], limit: f64) -> usize {
        let tris = triangles(rtin, need);
        let vertices: HashSet<Xy> = tris.iter().flatten().copied().collect();
        let mut edge_uses: HashMap<(Xy, Xy), u32> = HashMap::new();
        let mut doubled_area = 0;
        for t in &tris {
            let [a, b, c] = rtin.points(*t);
            let (b, c) = if orient(&a, &b, &c) > 0 {
                (b, c)
            } else {
                (c, b)
            };
            doubled_area += orient(&a, &b, &c);
            assert!(
                triangle_error(grid, &a, &b, &c, limit).is_some(),
                "{t:?} exceeds {limit}"
            );
            for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edge_uses.entry((p.min(q), p.max(q))).or_default() += 1;
                let (dx, dy) = (q.0 - p.0, q.1 - p.1);
                let steps = gcd(dx.abs(), dy.abs());
                for k in 1..steps {
                    let inner = (p.0 + k * dx / steps, p.1 + k * dy / steps);
                    assert!(!vertices.contains(&inner), "T-junction at {inner:?}");
                }
            }
        }
        assert!(edge_uses.values().all(|&n| n <= 2));
        assert_eq!(doubled_area as usize, 2 * grid.valid_cell_count());
        tris.len()
    }

    fn gcd(a: i64, b: i64) -> i64 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }

    #[test]
    fn both_refinements_conform_and_keep_the_limit() {
        let shapes = [(33, 33), (50, 37), (17, 64), (2, 9), (9, 2), (130, 70)];
        for (i, &(w, h)) in shapes.iter().enumerate() {
            for roughness in [0.0, 0.3, 1.0] {
                let smooth = terrain(w, h, roughness, i as u64);
                let holed = with_nodata_disc(smooth.clone(), w as f64 * 0.6, h as f64 * 0.4, 5.5);
                for spec in [smooth, holed] {
                    let g = grid(spec);
                    for limit in [0.05, 0.5, 3.0] {
                        let eight =
                            EdgeLimit::new(&EdgeMetric::Grid, Some(8), g.width(), g.height())
                                .unwrap();
                        for (edge, border) in [
                            (&NO_EDGE_LIMIT, false),
                            (&eight, false),
                            (&NO_EDGE_LIMIT, true),
                        ] {
                            let rtin = Rtin::new(&g, limit, edge, border);
                            let bottom_up = check_mesh(&g, &rtin, &rtin.saturate(), limit);
                            let top_down = check_mesh(&g, &rtin, &rtin.refine(), limit);
                            // Top-down splits only what bottom-up splits too.
                            assert!(top_down <= bottom_up, "{w}x{h}: {top_down} > {bottom_up}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_probe_picks_top_down_for_smooth_data_at_a_large_bound() {
        let g = grid(terrain(200, 150, 0.2, 7));
        let fraction = |limit| Rtin::new(&g, limit, &NO_EDGE_LIMIT, false).finest_split_fraction();
        assert!(fraction(20.0) < TOP_DOWN_BELOW);
        assert!(fraction(0.001) > TOP_DOWN_BELOW);
    }
}
