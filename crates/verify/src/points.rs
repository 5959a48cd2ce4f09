//! Scattered points against a TIN: every point is located with its own bucket grid over the
//! triangles and measured by `f64` barycentric interpolation, sharing nothing with the
//! decimator that built the TIN.
//!
//! Containment is certified: an orientation's sign is taken from the `f64` determinant
//! only when it exceeds the determinant's rounding bound (Shewchuk's static filter), and an
//! undecided sign counts as inside, so a point is measured against every triangle that may
//! contain it (on a shared edge, against both) and never against none that does.

use serde::Serialize;

/// What measuring points against a TIN found.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct PointsReport {
    /// Points measured.
    pub points: usize,
    /// Largest |z - TIN| found at any point inside the TIN.
    pub max_error: f64,
    /// The point with that error: its index, x, y, z, and the TIN's height there.
    pub worst: Option<(usize, [f64; 3], f64)>,
    /// Points no triangle contains (the TIN does not cover them), beyond the position
    /// tolerance.
    pub uncovered: usize,
    /// Points no triangle contains but within the position tolerance of one: measured
    /// against the nearest such triangle's plane.
    pub near_edge: usize,
    /// The first uncovered point, if any.
    pub first_uncovered: Option<(usize, [f64; 3])>,
    /// Triangles with zero or negative area (counter-clockwise in x right, y up is
    /// expected).
    pub bad_triangles: usize,
    /// The bound asked for.
    pub bound: f64,
    /// The breaklines' check, when breaklines were given (set by the caller from
    /// [`crate::verify_breaklines`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub breaklines: Option<crate::BreaklinesReport>,
}

impl PointsReport {
    /// Whether every point is covered, every triangle counter-clockwise and non-degenerate,
    /// every point within the bound, and every breakline present.
    pub fn passed(&self) -> bool {
        self.uncovered == 0
            && self.bad_triangles == 0
            && self.max_error <= self.bound
            && self.breaklines.as_ref().is_none_or(|b| b.passed())
    }
}

/// Measures every point `[x, y, z]` against the TIN `vertices` / `triangles` (corner
/// indices, counter-clockwise with x right and y up): the largest |z - TIN(x, y)|, the
/// points the TIN does not cover and the degenerate or clockwise triangles.
/// Coordinates are shifted to the vertices' lower-left corner first, so the arithmetic
/// keeps the precision of the TIN's extent rather than of its absolute coordinates.
///
/// A point in no triangle but within `tolerance` (a distance in x, y) of one is measured
/// against the plane of the nearest: the allowance for a file format that rounds
/// positions (float32), where a point on the TIN's outline may fall a rounding outside
/// it. Give 0 for formats that keep positions exactly.
///
/// # Panics
/// When a triangle names a vertex that does not exist.
pub fn verify_points(
    points: &[[f64; 3]],
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    bound: f64,
    tolerance: f64,
) -> PointsReport {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in vertices {
        for a in 0..2 {
            lo[a] = lo[a].min(v[a]);
            hi[a] = hi[a].max(v[a]);
        }
    }
    let local: Vec<[f64; 3]> = vertices
        .iter()
        .map(|v| [v[0] - lo[0], v[1] - lo[1], v[2]])
        .collect();
    let mut report = PointsReport {
        points: points.len(),
        max_error: 0.0,
        worst: None,
        uncovered: 0,
        near_edge: 0,
        first_uncovered: None,
        bad_triangles: 0,
        bound,
        breaklines: None,
    };
    let mut good: Vec<u32> = Vec::with_capacity(triangles.len());
    for (t, c) in triangles.iter().enumerate() {
        let [a, b, cc] = c.map(|k| local[k as usize]);
        if orient_sign(&a, &b, &cc) != Sign::Positive {
            report.bad_triangles += 1;
        } else {
            good.push(t as u32);
        }
    }
    let buckets = Buckets::new(&local, triangles, &good, [hi[0] - lo[0], hi[1] - lo[1]]);
    for (i, p) in points.iter().enumerate() {
        let q = [p[0] - lo[0], p[1] - lo[1], p[2]];
        let mut covered = false;
        let mut worst_here = (0.0f64, f64::NAN);
        for &t in buckets.candidates(&q) {
            let [a, b, c] = triangles[t as usize].map(|k| local[k as usize]);
            let signs = [
                orient_sign(&a, &b, &q),
                orient_sign(&b, &c, &q),
                orient_sign(&c, &a, &q),
            ];
            if signs.contains(&Sign::Negative) {
                continue;
            }
            covered = true;
            let surface = interpolate(&a, &b, &c, &q);
            let e = (q[2] - surface).abs();
            if e > worst_here.0 || worst_here.1.is_nan() {
                worst_here = (e.max(worst_here.0), surface);
            }
        }
        if !covered {
            match buckets.nearest(&q, tolerance, triangles, &local) {
                Some(t) => {
                    let [a, b, c] = triangles[t as usize].map(|k| local[k as usize]);
                    let surface = interpolate(&a, &b, &c, &q);
                    worst_here = ((q[2] - surface).abs(), surface);
                    report.near_edge += 1;
                }
                None => {
                    report.uncovered += 1;
                    report.first_uncovered.get_or_insert((i, *p));
                    continue;
                }
            }
        }
        if worst_here.0 > report.max_error || report.worst.is_none() {
            report.max_error = report.max_error.max(worst_here.0);
            report.worst = Some((i, *p, worst_here.1));
        }
    }
    report
}

/// The height of the plane through `abc` at `p`, by barycentric weights.
fn interpolate(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], p: &[f64; 3]) -> f64 {
    let area = det(a, b, c);
    let wa = det(b, c, p) / area;
    let wb = det(c, a, p) / area;
    let wc = 1.0 - wa - wb;
    wa * a[2] + wb * b[2] + wc * c[2]
}

fn det(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sign {
    Negative,
    Undecided,
    Positive,
}

/// The sign of the orientation of `abc`, when the `f64` determinant decides it: its
/// magnitude exceeds Shewchuk's bound `(3 + 16 eps) eps (|l| + |r|)` on its rounding.
fn orient_sign(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Sign {
    let l = (b[0] - a[0]) * (c[1] - a[1]);
    let r = (b[1] - a[1]) * (c[0] - a[0]);
    let d = l - r;
    let eps = f64::EPSILON / 2.0;
    let bound = (3.0 + 16.0 * eps) * eps * (l.abs() + r.abs());
    if d > bound {
        Sign::Positive
    } else if -d > bound {
        Sign::Negative
    } else {
        Sign::Undecided
    }
}

/// A uniform grid of buckets over the TIN's extent, each listing the triangles whose
/// bounding box meets it.
struct Buckets {
    size: f64,
    columns: usize,
    rows: usize,
    start: Vec<u32>,
    triangles: Vec<u32>,
}

impl Buckets {
    fn new(local: &[[f64; 3]], triangles: &[[u32; 3]], good: &[u32], extent: [f64; 2]) -> Self {
        // About two triangles per bucket.
        let area = (extent[0] * extent[1]).max(f64::MIN_POSITIVE);
        let size = (2.0 * area / good.len().max(1) as f64)
            .sqrt()
            .max(extent[0].max(extent[1]) / 4096.0)
            .max(f64::MIN_POSITIVE);
        let columns = ((extent[0] / size) as usize + 1).max(1);
        let rows = ((extent[1] / size) as usize + 1).max(1);
        let span = |t: u32| {
            let c = triangles[t as usize].map(|k| local[k as usize]);
            let cell = |v: f64, n: usize| ((v / size).floor().max(0.0) as usize).min(n - 1);
            let (x0, x1) = (
                cell(
                    c.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min),
                    columns,
                ),
                cell(
                    c.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max),
                    columns,
                ),
            );
            let (y0, y1) = (
                cell(c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min), rows),
                cell(
                    c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max),
                    rows,
                ),
            );
            (x0, x1, y0, y1)
        };
        let mut count = vec![0u32; columns * rows + 1];
        for &t in good {
            let (x0, x1, y0, y1) = span(t);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    count[y * columns + x + 1] += 1;
                }
            }
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut list = vec![0u32; *count.last().unwrap_or(&0) as usize];
        for &t in good {
            let (x0, x1, y0, y1) = span(t);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let at = &mut fill[y * columns + x];
                    list[*at as usize] = t;
                    *at += 1;
                }
            }
        }
        Buckets {
            size,
            columns,
            rows,
            start: count,
            triangles: list,
        }
    }

    /// The triangle nearest to `p` among those within `tolerance` of it (by distance to
    /// their sides), if any.
    fn nearest(
        &self,
        p: &[f64; 3],
        tolerance: f64,
        triangles: &[[u32; 3]],
        local: &[[f64; 3]],
    ) -> Option<u32> {
        if tolerance <= 0.0 {
            return None;
        }
        let mut best: Option<(f64, u32)> = None;
        for dy in [-tolerance, tolerance] {
            for dx in [-tolerance, tolerance] {
                for &t in self.candidates(&[p[0] + dx, p[1] + dy, 0.0]) {
                    let c = triangles[t as usize].map(|k| local[k as usize]);
                    let d = (0..3)
                        .map(|e| segment_distance(p, &c[e], &c[(e + 1) % 3]))
                        .fold(f64::INFINITY, f64::min);
                    if d <= tolerance && best.is_none_or(|(bd, bt)| d < bd || (d == bd && t < bt)) {
                        best = Some((d, t));
                    }
                }
            }
        }
        best.map(|(_, t)| t)
    }

    /// The triangles that may contain `p` (a point on a bucket's edge gets both buckets'
    /// lists through the rounding-tolerant cell range).
    fn candidates(&self, p: &[f64; 3]) -> &[u32] {
        let (fx, fy) = (p[0] / self.size, p[1] / self.size);
        if !(fx > -1.0 && fy > -1.0) {
            return &[];
        }
        let x = (fx.max(0.0) as usize).min(self.columns - 1);
        let y = (fy.max(0.0) as usize).min(self.rows - 1);
        let b = y * self.columns + x;
        &self.triangles[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

/// Distance in x, y from `p` to the segment `ab`.
fn segment_distance(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length2 = dx * dx + dy * dy;
    let s = if length2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - s * dx).powi(2) + (p[1] - a[1] - s * dy).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v = vec![
            [1e6, 5e6, 0.0],
            [1e6 + 10.0, 5e6, 10.0],
            [1e6 + 10.0, 5e6 + 10.0, 20.0],
            [1e6, 5e6 + 10.0, 10.0],
        ];
        (v, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn points_on_the_plane_pass_and_off_it_fail() {
        let (v, t) = square();
        // z = (x - x0) + (y - y0) is the plane through all four corners.
        let on = [[1e6 + 2.5, 5e6 + 7.0, 9.5], [1e6 + 5.0, 5e6 + 5.0, 10.0]];
        let r = verify_points(&on, &v, &t, 1e-9, 0.0);
        assert!(r.passed(), "{r:?}");
        let off = [[1e6 + 2.5, 5e6 + 7.0, 9.7]];
        let r = verify_points(&off, &v, &t, 0.1, 0.0);
        assert!(!r.passed());
        assert!((r.max_error - 0.2).abs() < 1e-6);
        assert_eq!(r.worst.unwrap().0, 0);
    }

    #[test]
    fn uncovered_points_and_bad_triangles_fail() {
        let (v, t) = square();
        let r = verify_points(&[[1e6 - 1.0, 5e6, 0.0]], &v, &t, 1.0, 0.0);
        assert_eq!(r.uncovered, 1);
        assert!(!r.passed());
        // Within the tolerance of the outline: measured against the nearest plane.
        let r = verify_points(&[[1e6 - 1e-3, 5e6 + 5.0, 5.0]], &v, &t, 1.0, 2e-3);
        assert_eq!((r.uncovered, r.near_edge), (0, 1));
        assert!(r.passed(), "{r:?}");
        let r = verify_points(
            &[[1e6 + 1.0, 5e6 + 0.5, 1.5]],
            &v,
            &[[0, 2, 1], [0, 2, 3]],
            1.0,
            0.0,
        );
        assert_eq!(r.bad_triangles, 1);
        assert!(!r.passed());
    }
}
