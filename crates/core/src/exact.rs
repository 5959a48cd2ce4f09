//! The exact error model: a triangle's error is measured over the original samples it
//! covers, with no accumulation (beyond the paper).

use crate::grid::MIN_EQUAL_RUN;
use crate::predicates::{orient, plane_gradient, Point};
use crate::{ErrorBound, Grid};

/// The exact above/below error of the plane through counter-clockwise triangle `abc` over
/// every grid sample in the closed triangle, or `None` as soon as either side exceeds
/// `limit`; on a grid with variables ([`Grid::with_variables`]), every variable within its
/// own limit too, the bound being the largest of the height's and the variables' errors
/// in height units (see `crate::variables`).
#[inline]
pub(crate) fn triangle_error(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    limit: f64,
) -> Option<ErrorBound> {
    let height = height_error(grid, a, b, c, limit)?;
    if grid.variables().is_empty() {
        return Some(height);
    }
    crate::variables::with_variables(grid, a, b, c, limit, height)
}

/// [`triangle_error`] of the height alone (or of a variable's own grid).
///
/// Which samples are inside is decided exactly (integer edge functions, row by row); the
/// plane is evaluated in `f64` from corner `a`. The triangle must lie in the grid's domain
/// (all its samples valid), which decimation guarantees.
pub(crate) fn height_error(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    limit: f64,
) -> Option<ErrorBound> {
    debug_assert!(orient(a, b, c) > 0);
    if limit == 0.0 && grid.integral_heights() {
        // Error 0 asked of integer heights: decided exactly, not within f64 rounding.
        return all_on_plane(grid, a, b, c).then_some(ErrorBound::default());
    }
    if orient(a, b, c) == 1 {
        // Doubled area 1: by Pick's theorem the corners are the only samples.
        if !grid.has_vertex_heights() {
            return error_at(a, b, c, [a, b, c], limit);
        }
        return error_at(a, b, c, &corner_samples(grid, [a, b, c]), limit);
    }
    if let Some(v) = flat_value(grid, a, b, c) {
        // Every sample, the corners included, is `v`: where the corners' heights are `v`
        // too, so is the plane, exactly as the scan below would find.
        debug_assert!(grid.has_vertex_heights() || (a.z == v && b.z == v && c.z == v));
        if a.z == v && b.z == v && c.z == v {
            return Some(ErrorBound::default());
        }
    }
    let g = plane_gradient(a, b, c);
    let width = grid.width() as usize;
    let values = grid.values();
    let (mut above, mut below) = (0.0f64, 0.0f64);
    let mut spans = RowSpans::new(a, b, c);
    for y in spans.rows() {
        let (lo, hi) = spans.next_span();
        if lo > hi {
            continue;
        }
        let row = &values[y as usize * width..][..width];
        let base = a.z + g[1] * (y - a.y) as f64;
        let mut measure = |x: i64| {
            let plane = base + g[0] * (x - a.x) as f64;
            let d = row[x as usize] - plane;
            // Comparisons rather than `f64::max`: one instruction each, the same result
            // (a NaN would be skipped either way).
            above = if d > above { d } else { above };
            below = if -d > below { -d } else { below };
        };
        match grid.equal_runs() {
            None => (lo..=hi).for_each(&mut measure),
            Some(runs) => {
                // Along a run of equal samples the computed plane is monotone in x (each
                // rounding step is), and so is the difference: its ends bound the rest,
                // bit for bit.
                let runs = &runs[y as usize * width..][..width];
                let mut x = lo;
                while x <= hi {
                    let run = runs[x as usize];
                    let end = if run >= MIN_EQUAL_RUN {
                        let end = (x + i64::from(run) - 1).min(hi);
                        measure(x);
                        measure(end);
                        end
                    } else {
                        let end = (x + i64::from(MIN_EQUAL_RUN) - 1).min(hi);
                        (x..=end).for_each(&mut measure);
                        end
                    };
                    x = end + 1;
                }
            }
        }
        if above > limit || below > limit {
            return None;
        }
    }
    Some(ErrorBound { above, below })
}

/// The exact above/below error of the plane through counter-clockwise triangle `abc` over
/// every grid sample in the closed triangle (no early stop), with the sample (row-major
/// index) of largest |sample - plane| among those that are not yet vertices
/// (`is_vertex`) with that error, `None` when every sample is one. The arithmetic is
/// [`triangle_error`]'s, so the bound is bit for bit the one it gives.
pub(crate) fn triangle_worst(
    grid: &Grid,
    a: &Point,
    b: &Point,
    c: &Point,
    is_vertex: &[bool],
) -> (ErrorBound, Option<(usize, f64)>) {
    debug_assert!(orient(a, b, c) > 0);
    let g = plane_gradient(a, b, c);
    let width = grid.width() as usize;
    let values = grid.values();
    let (mut above, mut below) = (0.0f64, 0.0f64);
    let mut worst = (-1.0f64, None);
    let mut spans = RowSpans::new(a, b, c);
    for y in spans.rows() {
        let (lo, hi) = spans.next_span();
        if lo > hi {
            continue;
        }
        let start = y as usize * width;
        let row = &values[start..][..width];
        let base = a.z + g[1] * (y - a.y) as f64;
        // Returns |d| at `x`, recording the bound and the worst non-vertex sample.
        let mut measure = |x: i64| {
            let plane = base + g[0] * (x - a.x) as f64;
            let d = row[x as usize] - plane;
            above = if d > above { d } else { above };
            below = if -d > below { -d } else { below };
            let e = d.abs();
            if e > worst.0 && !is_vertex[start + x as usize] {
                worst = (e, Some((start + x as usize, e)));
            }
        };
        match grid.equal_runs() {
            None => {
                // The row's largest |d| first, without a branch per sample; the worst
                // sample is looked for only on a row that can beat it (the same first
                // worst sample, and bit for bit the same bound, as one pass).
                let (up, down) =
                    row_extremes(&row[lo as usize..=hi as usize], base, g[0], lo - a.x);
                above = if up > above { up } else { above };
                below = if down > below { down } else { below };
                let e = if up > down { up } else { down };
                if e > worst.0 {
                    for x in lo..=hi {
                        let plane = base + g[0] * (x - a.x) as f64;
                        let e = (row[x as usize] - plane).abs();
                        if e > worst.0 && !is_vertex[start + x as usize] {
                            worst = (e, Some((start + x as usize, e)));
                        }
                    }
                }
            }
            Some(runs) => {
                // Along a run of equal samples |d| is largest at one of its ends (see
                // `triangle_error`); a vertex at an end hands that end to its neighbour.
                let runs = &runs[start..][..width];
                let mut x = lo;
                while x <= hi {
                    let run = runs[x as usize];
                    let end = if run >= MIN_EQUAL_RUN {
                        let end = (x + i64::from(run) - 1).min(hi);
                        for e in [x, x + 1, end - 1, end] {
                            if e >= x && e <= end {
                                measure(e);
                            }
                        }
                        end
                    } else {
                        let end = (x + i64::from(MIN_EQUAL_RUN) - 1).min(hi);
                        (x..=end).for_each(&mut measure);
                        end
                    };
                    x = end + 1;
                }
            }
        }
    }
    (ErrorBound { above, below }, worst.1)
}

/// The largest `d` and `-d` (each at least `-inf`) over `row`, where `d` is a sample less
/// the plane `base + gx * dx`, `dx` counted from `dx0` at the row's first sample: the
/// arithmetic of [`triangle_error`] per sample, in four independent lanes (a maximum does
/// not depend on the order it is taken in).
#[inline]
fn row_extremes(row: &[f64], base: f64, gx: f64, dx0: i64) -> (f64, f64) {
    let mut up = [f64::NEG_INFINITY; 4];
    let mut down = [f64::NEG_INFINITY; 4];
    let mut chunks = row.chunks_exact(4);
    let mut dx = dx0;
    for chunk in &mut chunks {
        for l in 0..4 {
            let d = chunk[l] - (base + gx * (dx + l as i64) as f64);
            up[l] = if d > up[l] { d } else { up[l] };
            down[l] = if -d > down[l] { -d } else { down[l] };
        }
        dx += 4;
    }
    for (l, &z) in chunks.remainder().iter().enumerate() {
        let d = z - (base + gx * (dx + l as i64) as f64);
        up[l] = if d > up[l] { d } else { up[l] };
        down[l] = if -d > down[l] { -d } else { down[l] };
    }
    let max = |v: [f64; 4]| {
        let (p, q) = (
            if v[0] > v[1] { v[0] } else { v[1] },
            if v[2] > v[3] { v[2] } else { v[3] },
        );
        if p > q {
            p
        } else {
            q
        }
    };
    (max(up), max(down))
}

/// The samples at the given vertices' positions, as points (their heights may differ, see
/// [`Grid::vertex_height`]).
pub(crate) fn corner_samples<const N: usize>(grid: &Grid, corners: [&Point; N]) -> [Point; N] {
    let width = grid.width() as i64;
    corners.map(|p| Point {
        z: grid.values()[(p.y * width + p.x) as usize],
        ..*p
    })
}

/// The above/below error of the plane through counter-clockwise triangle `abc` over the
/// given samples only (the caller knows they are all the grid samples in the closed
/// triangle), or `None` when either side exceeds `limit`. The arithmetic is
/// [`triangle_error`]'s, so both give identical results on the same samples.
pub(crate) fn error_at<'p>(
    a: &Point,
    b: &Point,
    c: &Point,
    samples: impl IntoIterator<Item = &'p Point>,
    limit: f64,
) -> Option<ErrorBound> {
    let g = plane_gradient(a, b, c);
    let (mut above, mut below) = (0.0f64, 0.0f64);
    for p in samples {
        let plane = (a.z + g[1] * (p.y - a.y) as f64) + g[0] * (p.x - a.x) as f64;
        let d = p.z - plane;
        above = above.max(d);
        below = below.max(-d);
    }
    (above <= limit && below <= limit).then_some(ErrorBound { above, below })
}

/// The value every sample in the bounding box of `abc` is known to have
/// ([`Grid::flat_value`]).
fn flat_value(grid: &Grid, a: &Point, b: &Point, c: &Point) -> Option<f64> {
    grid.flat_value(
        a.x.min(b.x).min(c.x),
        a.x.max(b.x).max(c.x),
        a.y.min(b.y).min(c.y),
        a.y.max(b.y).max(c.y),
    )
}

/// The columns inside a closed counter-clockwise triangle, row by row from its lowest row
/// to its highest, decided exactly and without a division per row: each edge's bound
/// `x >= ceil(..)` or `x <= floor(..)` is a floor quotient whose numerator grows by a
/// constant per row, so it is kept as quotient and remainder and stepped.
struct RowSpans {
    /// Per edge: the floor quotient of its bound on the current row.
    bounds: [FloorQuotient; 3],
    /// Per edge: whether it bounds the row from below (`lo = -quotient`) rather than from
    /// above (`hi = quotient`), or not at all (a horizontal edge).
    kind: [EdgeKind; 3],
    x_lo: i64,
    x_hi: i64,
    y0: i64,
    y1: i64,
    /// For a narrow triangle (see [`NARROW_SPAN`]), per edge its edge function at
    /// (`x_lo`, the current row) and its steps per column and per row, in place of
    /// `bounds` (which then stay unset): the span is found by testing the bounding box's
    /// columns, without the six divisions that set up `bounds`.
    narrow: Option<[EdgeFunction; 3]>,
}

/// Triangles at most this many columns wide find their rows' spans by testing each column
/// of their bounding box against the edge functions instead of stepping floor quotients,
/// whose set-up costs six 64-bit divisions; the same spans. Late in a greedy insertion
/// and in most removal holes at small bounds, triangles cover a handful of samples.
const NARROW_SPAN: i64 = 8;

/// `value + per_column * dx + per_row * dy >= 0` inside (or on) an edge.
#[derive(Clone, Copy)]
struct EdgeFunction {
    value: i64,
    per_column: i64,
    per_row: i64,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum EdgeKind {
    Lower,
    Upper,
    Horizontal,
}

/// `floor(n / d)` for a numerator `n` that grows by `step` per row, with `d > 0`.
#[derive(Clone, Copy, Default)]
struct FloorQuotient {
    quotient: i64,
    remainder: i64,
    divisor: i64,
    step_quotient: i64,
    step_remainder: i64,
}

impl FloorQuotient {
    fn new(n: i64, divisor: i64, step: i64) -> FloorQuotient {
        FloorQuotient {
            quotient: n.div_euclid(divisor),
            remainder: n.rem_euclid(divisor),
            divisor,
            step_quotient: step.div_euclid(divisor),
            step_remainder: step.rem_euclid(divisor),
        }
    }

    #[inline]
    fn step(&mut self) {
        self.quotient += self.step_quotient;
        self.remainder += self.step_remainder;
        if self.remainder >= self.divisor {
            self.remainder -= self.divisor;
            self.quotient += 1;
        }
    }
}

impl RowSpans {
    fn new(a: &Point, b: &Point, c: &Point) -> RowSpans {
        RowSpans::with_narrow_span(a, b, c, NARROW_SPAN)
    }

    /// [`RowSpans::new`], with triangles at most `narrow_span` columns wide taking the
    /// edge-function path.
    fn with_narrow_span(a: &Point, b: &Point, c: &Point, narrow_span: i64) -> RowSpans {
        let y0 = a.y.min(b.y).min(c.y);
        let (x_lo, x_hi) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        let mut bounds = [FloorQuotient::default(); 3];
        let mut kind = [EdgeKind::Horizontal; 3];
        if x_hi - x_lo <= narrow_span {
            // E(x, y) = (q.x - p.x)(y - p.y) - (q.y - p.y)(x - p.x) >= 0: left of (or on)
            // the counter-clockwise edge pq.
            let edge = |p: &Point, q: &Point| EdgeFunction {
                value: (q.x - p.x) * (y0 - p.y) - (q.y - p.y) * (x_lo - p.x),
                per_column: p.y - q.y,
                per_row: q.x - p.x,
            };
            return RowSpans {
                bounds,
                kind,
                x_lo,
                x_hi,
                y0,
                y1: a.y.max(b.y).max(c.y),
                narrow: Some([edge(a, b), edge(b, c), edge(c, a)]),
            };
        }
        for (k, (p, q)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
            // The edge function E(x) = e0 + s * x must be >= 0, with e0 growing by q.x - p.x
            // per row. A horizontal edge (s = 0) holds on every row of the triangle: its
            // e0 has the sign it has at the third corner, which is positive.
            let s = p.y - q.y;
            let e0 = (q.x - p.x) * (y0 - p.y) + (q.y - p.y) * p.x;
            if s > 0 {
                // x >= ceil(-e0 / s) = -floor(e0 / s)
                bounds[k] = FloorQuotient::new(e0, s, q.x - p.x);
                kind[k] = EdgeKind::Lower;
            } else if s < 0 {
                // x <= floor(e0 / -s)
                bounds[k] = FloorQuotient::new(e0, -s, q.x - p.x);
                kind[k] = EdgeKind::Upper;
            }
        }
        RowSpans {
            bounds,
            kind,
            x_lo,
            x_hi,
            y0,
            y1: a.y.max(b.y).max(c.y),
            narrow: None,
        }
    }

    /// The triangle's rows, lowest first; call [`RowSpans::next_span`] once for each.
    fn rows(&self) -> std::ops::RangeInclusive<i64> {
        self.y0..=self.y1
    }

    /// The columns `lo..=hi` of the next row inside the triangle (`lo > hi` when none).
    #[inline]
    fn next_span(&mut self) -> (i64, i64) {
        if let Some(edges) = &mut self.narrow {
            let inside = |dx: i64| edges.iter().all(|e| e.value + e.per_column * dx >= 0);
            let width = self.x_hi - self.x_lo;
            // A row of a convex triangle: its columns inside are one run.
            let span = (0..=width).find(|&dx| inside(dx)).map(|lo| {
                let hi = (lo..=width).rev().find(|&dx| inside(dx)).unwrap_or(lo);
                (self.x_lo + lo, self.x_lo + hi)
            });
            for e in edges.iter_mut() {
                e.value += e.per_row;
            }
            return span.unwrap_or((self.x_hi + 1, self.x_hi));
        }
        let (mut lo, mut hi) = (self.x_lo, self.x_hi);
        for k in 0..3 {
            let q = self.bounds[k].quotient;
            match self.kind[k] {
                EdgeKind::Lower => lo = lo.max(-q),
                EdgeKind::Upper => hi = hi.min(q),
                EdgeKind::Horizontal => {}
            }
            self.bounds[k].step();
        }
        (lo, hi)
    }
}

/// Whether every sample of the closed counter-clockwise triangle `abc` lies exactly on the
/// plane through its corners, for a grid of [`Grid::integral_heights`]: the normal
/// `(b - a) x (c - a)` and each sample's offset from `a` are integers, and their dot
/// product is computed exactly in `i128`.
fn all_on_plane(grid: &Grid, a: &Point, b: &Point, c: &Point) -> bool {
    if flat_value(grid, a, b, c).is_some() {
        return true;
    }
    // Integral heights are below 2^50 in magnitude: exact through `i64`, whose conversion
    // is one instruction (to `i128` it is a library call).
    let z = |v: f64| i128::from(v as i64);
    let (ux, uy, uz) = ((b.x - a.x) as i128, (b.y - a.y) as i128, z(b.z) - z(a.z));
    let (vx, vy, vz) = ((c.x - a.x) as i128, (c.y - a.y) as i128, z(c.z) - z(a.z));
    let normal = [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx];
    let width = grid.width() as usize;
    let values = grid.values();
    let mut spans = RowSpans::new(a, b, c);
    for y in spans.rows() {
        let (lo, hi) = spans.next_span();
        if lo > hi {
            continue;
        }
        let row = &values[y as usize * width..][..width];
        let dy = normal[1] * (y - a.y) as i128;
        let on_plane = |x: i64| {
            normal[0] * (x - a.x) as i128 + dy + normal[2] * (z(row[x as usize]) - z(a.z)) == 0
        };
        match grid.equal_runs() {
            None => {
                if !(lo..=hi).all(on_plane) {
                    return false;
                }
            }
            Some(runs) => {
                // Along a run of equal samples the offset from the plane is linear in x:
                // zero at both ends means zero throughout.
                let runs = &runs[y as usize * width..][..width];
                let mut x = lo;
                while x <= hi {
                    let end = (x + i64::from(runs[x as usize]) - 1).min(hi);
                    if !on_plane(x) || !on_plane(end) {
                        return false;
                    }
                    x = end + 1;
                }
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(w: u32, h: u32, f: impl Fn(i64, i64) -> f64) -> Grid {
        let v = (0..h as i64)
            .flat_map(|y| (0..w as i64).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Grid::new(w, h, v).unwrap()
    }

    fn pt(g: &Grid, x: i64, y: i64) -> Point {
        Point {
            x,
            y,
            z: g.get(x as u32, y as u32).unwrap(),
        }
    }

    #[test]
    fn matches_a_per_sample_scan() {
        let g = grid(23, 19, |x, y| {
            ((x * 7 + y * 13) % 11) as f64 - 0.3 * x as f64
        });
        let tris = [
            [(0, 0), (22, 3), (5, 18)],
            [(3, 3), (4, 3), (3, 4)],
            [(1, 17), (20, 0), (21, 18)],
        ];
        for t in tris {
            let [a, b, c] = t.map(|(x, y)| pt(&g, x, y));
            let got = triangle_error(&g, &a, &b, &c, f64::INFINITY).unwrap();
            let gr = plane_gradient(&a, &b, &c);
            let (mut up, mut down) = (0.0f64, 0.0f64);
            for y in 0..19 {
                for x in 0..23 {
                    let p = Point { x, y, z: 0.0 };
                    if orient(&a, &b, &p) >= 0 && orient(&b, &c, &p) >= 0 && orient(&c, &a, &p) >= 0
                    {
                        let d = g.get(x as u32, y as u32).unwrap()
                            - (a.z + gr[0] * (x - a.x) as f64 + gr[1] * (y - a.y) as f64);
                        up = up.max(d);
                        down = down.max(-d);
                    }
                }
            }
            assert_eq!((got.above, got.below), (up, down));
        }
    }

    #[test]
    fn flat_ground_shortcuts_match_a_per_sample_scan() {
        // Mostly flat (so the grid keeps its runs and flat blocks), with a bump, a ramp
        // and a step: every triangle of a lattice of corners, measured by the shortcuts
        // (runs, flat blocks, and the exact planarity test at 0) and by a plain scan.
        let g = grid(70, 50, |x, y| {
            if (30..36).contains(&x) && (20..24).contains(&y) {
                ((x * 3 + y) % 5) as f64
            } else if x >= 50 {
                (y / 7) as f64
            } else if y >= 40 {
                2.0
            } else {
                0.0
            }
        });
        assert!(g.equal_runs().is_some());
        let corners: Vec<(i64, i64)> = (0..70)
            .step_by(9)
            .flat_map(|x| (0..50).step_by(7).map(move |y| (x, y)))
            .collect();
        let mut checked = 0;
        for (i, &a) in corners.iter().enumerate() {
            for (j, &b) in corners.iter().enumerate().skip(i + 1) {
                for &c in &corners[j + 1..] {
                    let (a, b, c) = (pt(&g, a.0, a.1), pt(&g, b.0, b.1), pt(&g, c.0, c.1));
                    let (b, c) = match orient(&a, &b, &c) {
                        o if o > 0 => (b, c),
                        o if o < 0 => (c, b),
                        _ => continue,
                    };
                    let gr = plane_gradient(&a, &b, &c);
                    let (mut up, mut down) = (0.0f64, 0.0f64);
                    for y in 0..50 {
                        for x in 0..70 {
                            let p = Point { x, y, z: 0.0 };
                            if orient(&a, &b, &p) >= 0
                                && orient(&b, &c, &p) >= 0
                                && orient(&c, &a, &p) >= 0
                            {
                                let base = a.z + gr[1] * (y - a.y) as f64;
                                let d = g.get(x as u32, y as u32).unwrap()
                                    - (base + gr[0] * (x - a.x) as f64);
                                up = if d > up { d } else { up };
                                down = if -d > down { -d } else { down };
                            }
                        }
                    }
                    let got = triangle_error(&g, &a, &b, &c, f64::INFINITY).unwrap();
                    assert_eq!(
                        (got.above.to_bits(), got.below.to_bits()),
                        (up.to_bits(), down.to_bits()),
                        "{a:?} {b:?} {c:?}"
                    );
                    let flat = triangle_error(&g, &a, &b, &c, 0.0).is_some();
                    assert_eq!(flat, up == 0.0 && down == 0.0, "{a:?} {b:?} {c:?}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
        // A run of equal samples that only starts on a tilted plane: z = x through
        // (0, 0, 0), (12, 0, 12), (0, 4, 0), over zeros.
        let g = grid(20, 6, |x, y| if (x, y) == (12, 0) { 12.0 } else { 0.0 });
        assert!(g.equal_runs().is_some());
        let (a, b, c) = (pt(&g, 0, 0), pt(&g, 0, 4), pt(&g, 12, 0));
        let (b, c) = if orient(&a, &b, &c) > 0 {
            (b, c)
        } else {
            (c, b)
        };
        assert!(triangle_error(&g, &a, &b, &c, 0.0).is_none());
    }

    #[test]
    fn row_spans_are_the_samples_inside() {
        // Every triangle on a small lattice, against the three orientation tests per sample.
        let corners: Vec<(i64, i64)> = (-3..4).flat_map(|x| (-2..3).map(move |y| (x, y))).collect();
        let p = |(x, y): (i64, i64)| Point { x, y, z: 0.0 };
        let mut checked = 0;
        for (i, &a) in corners.iter().enumerate() {
            for (j, &b) in corners.iter().enumerate().skip(i + 1) {
                for &c in &corners[j + 1..] {
                    let (a, b, c) = (p(a), p(b), p(c));
                    let (b, c) = match orient(&a, &b, &c) {
                        o if o > 0 => (b, c),
                        o if o < 0 => (c, b),
                        _ => continue,
                    };
                    for narrow_span in [0, i64::MAX] {
                        let mut spans = RowSpans::with_narrow_span(&a, &b, &c, narrow_span);
                        for y in spans.rows() {
                            let (lo, hi) = spans.next_span();
                            for x in -5..6 {
                                let q = Point { x, y, z: 0.0 };
                                let inside = orient(&a, &b, &q) >= 0
                                    && orient(&b, &c, &q) >= 0
                                    && orient(&c, &a, &q) >= 0;
                                assert_eq!(
                                    inside,
                                    (lo..=hi).contains(&x),
                                    "{a:?} {b:?} {c:?} at {x},{y}, narrow span {narrow_span}"
                                );
                            }
                        }
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 5000, "{checked}");
    }

    #[test]
    fn stops_early_beyond_the_limit() {
        let g = grid(10, 10, |x, y| if (x, y) == (4, 4) { 9.0 } else { 0.0 });
        let (a, b, c) = (pt(&g, 0, 0), pt(&g, 9, 0), pt(&g, 0, 9));
        assert!(triangle_error(&g, &a, &b, &c, 8.0).is_none());
        assert_eq!(triangle_error(&g, &a, &b, &c, 9.0).unwrap().above, 9.0);
    }
}
