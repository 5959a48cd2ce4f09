//! Marching triangles: where a level crosses an edge, and the segment in one triangle.
//!
//! # The symbolic perturbation
//! A height equal to the level counts as *above* it: every height is treated as
//! `z + δ` for an infinitesimal `δ > 0`. Then no vertex is ever on the level, every
//! triangle is either uncut or cut across exactly two of its edges, and every crossed edge
//! has one end strictly below the level and one at or above it. Consequences:
//! - A crossing point is the interpolated point `lo + t (hi − lo)` with
//!   `t = (level − z_lo) / (z_hi − z_lo)` in `(0, 1]`; at `t = 1` (the upper end is at the
//!   level) the point is that vertex exactly. The contour then touches the vertex, and
//!   several consecutive crossings of the edges around it coincide there; joining
//!   collapses them to one point (see [`crate::contour`]).
//! - A triangle flat at the level is "above": it has no segment. The contour follows the
//!   boundary of the region at or above the level, so it runs along the edge of a flat
//!   area at the level, not through it.
//! - Saddles need no rule: within one triangle the function is linear, so there is no
//!   ambiguous case, and since every crossed edge has exactly one crossing, lines that meet
//!   at a saddle vertex (at the level) are joined unambiguously through distinct edges.

/// The perturbation: a height equal to the level counts as above it.
#[inline]
pub(crate) fn below(z: f64, level: f64) -> bool {
    z < level
}

/// The point where `level` crosses the edge `p`–`q`, one of whose ends is below the level.
///
/// Computed from the lower end to the upper one, so both triangles of an edge get the same
/// bits; the upper end itself when it is at the level.
#[inline]
pub(crate) fn crossing_point(p: [f64; 3], q: [f64; 3], level: f64) -> [f64; 2] {
    let (lo, hi) = if below(p[2], level) { (p, q) } else { (q, p) };
    let t = (level - lo[2]) / (hi[2] - lo[2]);
    if t >= 1.0 {
        [hi[0], hi[1]]
    } else {
        [lo[0] + t * (hi[0] - lo[0]), lo[1] + t * (hi[1] - lo[1])]
    }
}

/// The two local edges (`k` joins corners `k` and `k + 1`) that `level` crosses in the
/// triangle with corners `c`, as `(entry, exit)` so that the ground at or above the level is
/// on the left of entry → exit; `None` when the level does not cut the triangle.
///
/// The orientation is read from the corners' coordinates; a degenerate (zero-area)
/// triangle is taken as counter-clockwise.
#[inline]
pub(crate) fn segment(c: [[f64; 3]; 3], level: f64) -> Option<(usize, usize)> {
    let b = c.map(|p| below(p[2], level));
    let lone = if b[0] == b[1] {
        if b[1] == b[2] {
            return None;
        }
        2
    } else if b[0] == b[2] {
        1
    } else {
        0
    };
    // Edges `lone` and `lone + 2` meet at the lone corner. Counter-clockwise with the lone
    // corner above, entering through `lone` and leaving through `lone + 2` keeps the
    // corner on the left.
    let cross =
        (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]);
    let ccw = cross >= 0.0;
    let forward = ccw != b[lone];
    let (i, j) = (lone, (lone + 2) % 3);
    Some(if forward { (i, j) } else { (j, i) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn left_of(a: [f64; 2], b: [f64; 2], p: [f64; 3]) -> bool {
        (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0.0
    }

    #[test]
    fn high_ground_on_the_left_in_every_configuration() {
        let ccw = [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]];
        for flip in [false, true] {
            for pattern in 1..7u8 {
                let mut c = [[0.0; 3]; 3];
                for k in 0..3 {
                    let xy = if flip { ccw[2 - k] } else { ccw[k] };
                    let z = if pattern & (1 << k) != 0 { 10.0 } else { 0.0 };
                    c[k] = [xy[0], xy[1], z];
                }
                let (i, j) = segment(c, 5.0).expect("cut");
                let a = crossing_point(c[i], c[(i + 1) % 3], 5.0);
                let b = crossing_point(c[j], c[(j + 1) % 3], 5.0);
                for p in c {
                    assert_eq!(left_of(a, b, p), p[2] >= 5.0, "{c:?}");
                }
            }
        }
    }

    #[test]
    fn uncut_and_flat_triangles() {
        let c = [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]];
        assert_eq!(segment(c, 5.0), None);
        assert_eq!(segment(c, 4.0), None);
        assert!(segment(c, 5.5).is_none());
    }

    #[test]
    fn crossing_points_are_exact_at_the_upper_end() {
        let p = [0.1, 0.7, 1.0];
        let q = [0.3, 0.9, 2.0];
        assert_eq!(crossing_point(p, q, 2.0), [0.3, 0.9]);
        assert_eq!(crossing_point(q, p, 2.0), [0.3, 0.9]);
        assert_eq!(crossing_point(p, q, 1.5), crossing_point(q, p, 1.5));
        let m = crossing_point([0.0, 0.0, 0.0], [4.0, 2.0, 8.0], 2.0);
        assert_eq!(m, [1.0, 0.5]);
    }
}
