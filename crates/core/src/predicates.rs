//! Exact geometric predicates on integer grid positions.
//!
//! Grid positions are integers below 2^32 with `width * height < 2^32`. In an orientation
//! determinant every product pairs an x-difference with a y-difference, so each product is
//! below `width * height` and the determinant is exact in `i64`.

/// A point of the grid: integer position and a height (a sample's value, or a vertex's
/// height, see [`crate::VertexHeights`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Point {
    pub x: i64,
    pub y: i64,
    pub z: f64,
}

/// Twice the signed area of triangle `abc`: positive when counter-clockwise in grid
/// coordinates, zero when collinear. Exact.
#[inline]
pub(crate) fn orient(a: &Point, b: &Point, c: &Point) -> i64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// Whether `p` lies in the closed counter-clockwise triangle `abc`. Exact.
#[inline]
pub(crate) fn in_closed_triangle(a: &Point, b: &Point, c: &Point, p: &Point) -> bool {
    orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0
}

/// The gradient `(dz/dx, dz/dy)` of the plane through a non-degenerate triangle.
#[inline]
pub(crate) fn plane_gradient(a: &Point, b: &Point, c: &Point) -> [f64; 2] {
    let d = orient(a, b, c) as f64;
    let (bx, by) = ((b.x - a.x) as f64, (b.y - a.y) as f64);
    let (cx, cy) = ((c.x - a.x) as f64, (c.y - a.y) as f64);
    let (bz, cz) = (b.z - a.z, c.z - a.z);
    [(bz * cy - cz * by) / d, (cz * bx - bz * cx) / d]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: i64, y: i64, z: f64) -> Point {
        Point { x, y, z }
    }

    #[test]
    fn orientation_signs() {
        let (a, b, c) = (p(0, 0, 0.0), p(1, 0, 0.0), p(0, 1, 0.0));
        assert_eq!(orient(&a, &b, &c), 1);
        assert_eq!(orient(&a, &c, &b), -1);
        assert_eq!(orient(&a, &b, &p(5, 0, 0.0)), 0);
    }

    #[test]
    fn closed_triangle_includes_its_boundary() {
        let (a, b, c) = (p(0, 0, 0.0), p(4, 0, 0.0), p(0, 4, 0.0));
        assert!(in_closed_triangle(&a, &b, &c, &p(2, 2, 0.0)));
        assert!(in_closed_triangle(&a, &b, &c, &p(0, 0, 0.0)));
        assert!(in_closed_triangle(&a, &b, &c, &p(1, 1, 0.0)));
        assert!(!in_closed_triangle(&a, &b, &c, &p(3, 2, 0.0)));
    }

    #[test]
    fn gradient_of_a_plane() {
        let f = |x: i64, y: i64| p(x, y, 3.0 + 2.0 * x as f64 - 0.5 * y as f64);
        let g = plane_gradient(&f(1, 1), &f(7, 2), &f(3, 9));
        assert!((g[0] - 2.0).abs() < 1e-12 && (g[1] + 0.5).abs() < 1e-12);
    }

    #[test]
    fn large_coordinates_stay_exact() {
        let (a, b, c) = (p(0, 0, 0.0), p(65_535, 1, 0.0), p(65_534, 1, 0.0));
        assert_eq!(orient(&a, &b, &c), 1);
    }
}
