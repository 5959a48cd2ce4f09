//! Exact integer orientation and the linear interpolation it yields.
//!
//! Positions are grid positions (`0 <= x, y < 2^32`), so coordinate differences fit in 33
//! bits and every product in 66: `i128` never overflows and every test is exact.

/// Twice the signed area of triangle `abc`:
/// `(b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)`.
///
/// Positive when `a, b, c` turn counter-clockwise in grid coordinates, negative when
/// clockwise, zero when collinear. Exact for coordinates of magnitude below 2^62.
pub(crate) fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i128 {
    let [ax, ay] = a.map(i128::from);
    let [bx, by] = b.map(i128::from);
    let [cx, cy] = c.map(i128::from);
    (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
}

/// Linear interpolation of heights `z` at a point with barycentric `weights`.
///
/// `weights = [orient(b, c, p), orient(c, a, p), orient(a, b, p)]`, all multiplied by the same
/// sign so that they are `>= 0` with a positive sum (the point is in the closed triangle).
/// At a vertex (the two other weights are zero) the vertex height is returned exactly;
/// elsewhere `(wa * za + wb * zb + wc * zc) / (wa + wb + wc)` in `f64`, exact up to rounding
/// while the weights are below 2^53.
pub(crate) fn interpolate(weights: [i64; 3], z: [f64; 3]) -> f64 {
    let [wa, wb, wc] = weights;
    match (wa, wb, wc) {
        (_, 0, 0) => z[0],
        (0, _, 0) => z[1],
        (0, 0, _) => z[2],
        _ => {
            // Relative to the first corner, so a flat triangle interpolates exactly.
            let sum = (wa + wb + wc) as f64;
            z[0] + (wb as f64 * (z[1] - z[0]) + wc as f64 * (z[2] - z[0])) / sum
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient_signs() {
        assert_eq!(orient([0, 0], [1, 0], [0, 1]), 1);
        assert_eq!(orient([0, 0], [0, 1], [1, 0]), -1);
        assert_eq!(orient([0, 0], [1, 1], [2, 2]), 0);
        assert_eq!(orient([0, 0], [4, 0], [0, 3]), 12);
    }

    #[test]
    fn orient_is_exact_for_large_grid_coordinates() {
        let m = i64::from(u32::MAX);
        // Twice the area of the half-square with legs 2^32 - 1.
        assert_eq!(
            orient([0, 0], [m, 0], [0, m]),
            i128::from(m) * i128::from(m)
        );
        // m * (m - 2) - (m - 1)^2 = -1: a sliver of area 1/2, where f64 would give 0.
        assert_eq!(orient([0, 0], [m, m - 1], [m - 1, m - 2]), -1);
        assert_eq!(orient([0, 0], [m - 1, m - 2], [m, m - 1]), 1);
        assert_eq!(orient([0, 0], [m, m], [m - 1, m - 1]), 0);
    }

    #[test]
    fn interpolation_at_vertices_is_exact() {
        let z = [0.1, 0.2, 0.3];
        assert_eq!(interpolate([7, 0, 0], z), 0.1);
        assert_eq!(interpolate([0, 7, 0], z), 0.2);
        assert_eq!(interpolate([0, 0, 7], z), 0.3);
    }

    #[test]
    fn interpolation_is_linear() {
        // Midpoint of the edge a-b, and the centroid.
        assert_eq!(interpolate([1, 1, 0], [2.0, 4.0, 100.0]), 3.0);
        assert_eq!(interpolate([1, 1, 1], [3.0, 6.0, 9.0]), 6.0);
        assert_eq!(interpolate([3, 1, 0], [0.0, 8.0, 100.0]), 2.0);
    }
}
