//! A coarse initial mesh: a right-triangulated irregular network (RTIN, the longest-edge
//! bisection hierarchy of a power-of-two square) refined only where a triangle's exact
//! error exceeds the limit or it would cover a nodata cell (beyond the paper; issue 3).
//!
//! Vertex removal from the full grid costs time per sample even where the surface is
//! smooth. Starting from the coarsest RTIN whose every triangle is within the limit skips
//! most of those removals; decimation then continues from it as from the full grid.
//!
//! # Conformity
//! Each sample inside the top square is the hypotenuse midpoint of exactly one *diamond*
//! (the one or two triangles sharing that hypotenuse). A diamond is split when either of
//! its triangles must split or when any of its children's diamonds is split; computing
//! this bottom-up, level by level, makes both triangles of every diamond agree, so the
//! emitted triangles meet edge to edge (no T-junctions). This is the error saturation of
//! RTIN terrain meshes (e.g. Mapbox's martini), here with an exact error.
//!
//! # Guarantees
//! Every emitted triangle lies in the domain (all cells in its bounding box are valid) and
//! its exact error is within the limit; every valid cell is covered; every sample where
//! the domain's outline turns or pinches is a vertex (a sample inside an emitted edge has
//! all four cells around it valid, or lies on a straight stretch of the grid's border).

use crate::exact::triangle_error;
use crate::mesh::CompactBound;
use crate::predicates::{orient, Point};
use crate::Grid;

type Xy = (i64, i64);

/// Triangles (counter-clockwise sample indices) of the coarsest conforming RTIN over the
/// grid's domain whose triangles all have exact error at most `limit`, with those errors.
///
/// Triangles with an edge longer than `sqrt(max_edge_squared)` sample spacings split too.
/// With `full_border`, every triangle that reaches the grid's outer rows or columns is a
/// half cell, so the strip of cells along the border is triangulated as in the full grid
/// (what [`crate::decimate_with_border`] needs to remove border samples inside the strip).
pub(crate) fn rtin_triangles(
    grid: &Grid,
    limit: f64,
    max_edge_squared: i64,
    full_border: bool,
) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
    let rtin = Rtin::new(grid, limit, max_edge_squared, full_border);
    let need = rtin.saturate();
    let s = rtin.size;
    let halves = [((0, 0), (s, s), (s, 0)), ((s, s), (0, 0), (0, s))];
    // Count first so that the arrays are allocated once, at their size: at small bounds
    // they hold nearly two triangles per sample, and doubling growth would waste up to half.
    let mut count = 0;
    for (a, b, c) in halves {
        rtin.emit(a, b, c, &need, &mut |_| count += 1);
    }
    let mut out = (Vec::with_capacity(count), Vec::with_capacity(count));
    for (a, b, c) in halves {
        rtin.emit(a, b, c, &need, &mut |t| rtin.push(t, &mut out));
    }
    out
}

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
    /// Triangles with a longer (squared) hypotenuse always split.
    max_edge_squared: i64,
}

impl<'g> Rtin<'g> {
    fn new(grid: &'g Grid, limit: f64, max_edge_squared: i64, full_border: bool) -> Rtin<'g> {
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
            max_edge_squared,
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
    /// in full-border mode, its hypotenuse is too long, or its exact error exceeds the limit.
    fn must_split(&self, t: [Xy; 3]) -> bool {
        let (x0, x1, y0, y1) = bbox(t);
        if self.full_border && (x0 == 0 || y0 == 0 || x1 == self.max_x || y1 == self.max_y) {
            return true;
        }
        // The hypotenuse (the longest edge) is the one between t[0] and t[1].
        let (dx, dy) = (t[0].0 - t[1].0, t[0].1 - t[1].1);
        if dx * dx + dy * dy > self.max_edge_squared {
            return true;
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
            z: self.grid.values()[self.index(p)],
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
