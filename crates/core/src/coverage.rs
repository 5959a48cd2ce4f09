//! The samples a triangle covers, as the exact error model measures them: a grid's lattice
//! samples in the triangle, or the scattered points charged to the hole being filled.

use crate::exact::{corner_samples, triangle_error};
use crate::predicates::{in_closed_triangle, plane_gradient, Point};
use crate::{ErrorBound, Grid};

/// The original samples a new triangle of a hole must come within the bound of.
pub(crate) trait Coverage {
    /// The exact above/below error of the plane through counter-clockwise triangle `abc`
    /// over every sample in the closed triangle, or `None` once either side exceeds
    /// `limit`.
    fn triangle_error(&self, a: &Point, b: &Point, c: &Point, limit: f64) -> Option<ErrorBound>;
    /// Whether every height is an integer, so that an error of 0 is decided exactly.
    fn integral_heights(&self) -> bool;
    /// Whether vertex heights differ from their samples (raised, see
    /// [`crate::VertexHeights`]).
    fn has_vertex_heights(&self) -> bool;
    /// The samples at the given vertices' positions.
    fn corner_samples(&self, corners: [&Point; 3]) -> [Point; 3];
    /// Whether extra variables ride on the heights (several variables over one mesh).
    fn has_variables(&self) -> bool {
        false
    }
    /// Whether some extra variable already fails at `centre`, a sample in the closed
    /// triangle `abc` (a cheap rejection before the scan; see
    /// `crate::variables::centre_exceeds`). Never, without variables.
    fn variables_refuse_at(
        &self,
        _a: &Point,
        _b: &Point,
        _c: &Point,
        _centre: &Point,
        _cap: f64,
    ) -> bool {
        false
    }
}

impl Coverage for Grid {
    #[inline]
    fn triangle_error(&self, a: &Point, b: &Point, c: &Point, limit: f64) -> Option<ErrorBound> {
        triangle_error(self, a, b, c, limit)
    }

    #[inline]
    fn integral_heights(&self) -> bool {
        Grid::integral_heights(self)
    }

    #[inline]
    fn has_vertex_heights(&self) -> bool {
        Grid::has_vertex_heights(self)
    }

    #[inline]
    fn corner_samples(&self, corners: [&Point; 3]) -> [Point; 3] {
        corner_samples(self, corners)
    }

    #[inline]
    fn has_variables(&self) -> bool {
        self.variable_count() > 0
    }

    fn variables_refuse_at(
        &self,
        a: &Point,
        b: &Point,
        c: &Point,
        centre: &Point,
        cap: f64,
    ) -> bool {
        self.has_variables() && crate::variables::centre_exceeds(self, a, b, c, centre, cap)
    }
}

/// The scattered points of one hole: the removed vertex and the points charged to its
/// star's triangles. Every point the hole's new triangles cover is among them (a point on
/// the hole's outline may be charged to the triangle outside; the outline's edges stay, so
/// its error does not change).
#[derive(Debug, Default)]
pub(crate) struct HolePoints {
    pub(crate) points: Vec<Point>,
}

impl Coverage for HolePoints {
    fn triangle_error(&self, a: &Point, b: &Point, c: &Point, limit: f64) -> Option<ErrorBound> {
        // `error_at`'s arithmetic, fused with the point-in-triangle test: a bounding-box
        // test first (most of a large hole's points lie outside a candidate), and a stop
        // as soon as either side exceeds the limit.
        let (x_lo, x_hi) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        let (y_lo, y_hi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let g = plane_gradient(a, b, c);
        let (mut above, mut below) = (0.0f64, 0.0f64);
        for p in &self.points {
            if p.x < x_lo
                || p.x > x_hi
                || p.y < y_lo
                || p.y > y_hi
                || !in_closed_triangle(a, b, c, p)
            {
                continue;
            }
            let plane = (a.z + g[1] * (p.y - a.y) as f64) + g[0] * (p.x - a.x) as f64;
            let d = p.z - plane;
            above = above.max(d);
            below = below.max(-d);
            if above > limit || below > limit {
                return None;
            }
        }
        Some(ErrorBound { above, below })
    }

    fn integral_heights(&self) -> bool {
        false
    }

    fn has_vertex_heights(&self) -> bool {
        false
    }

    fn corner_samples(&self, corners: [&Point; 3]) -> [Point; 3] {
        corners.map(|p| *p)
    }
}
