//! One contour line: its level, its points, and the TIN edge under each point.

/// A contour line at one level: a path through the mesh, open or closed.
///
/// # Guarantees
/// - Every point lies on a mesh edge (given by [`Polyline::edges`]) where the linear
///   interpolation of the edge's two heights equals the level: the edge has one end below
///   the level and the other at or above it, and the point is the interpolated crossing
///   (exactly the upper end when that end is at the level).
/// - A closed line's first and last points are equal (and name the same edge); it has at
///   least three points.
/// - An open line's two end points lie on boundary edges (edges of one triangle: the
///   domain's outline or a nodata hole's); all its other points lie on interior edges.
/// - No two consecutive points are equal, so every segment has a positive length.
/// - The ground at or above the level is on the left of the direction of travel, when the
///   mesh's triangles are non-degenerate and the plane is seen with x to the right and y
///   up (so rings around peaks run counter-clockwise).
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    pub(crate) level: f64,
    pub(crate) points: Vec<[f64; 2]>,
    pub(crate) edges: Vec<[u32; 2]>,
    pub(crate) closed: bool,
}

impl Polyline {
    /// The contour level.
    pub fn level(&self) -> f64 {
        self.level
    }

    /// The points, in the mesh's coordinates.
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// For each point, the mesh edge it lies on, as `[smaller vertex, larger vertex]`.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// Whether the line is a closed ring (first point == last point).
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Number of segments: points − 1.
    pub fn segment_count(&self) -> usize {
        self.points.len() - 1
    }

    /// Total length of the segments.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }

    /// Reverses the direction of travel (the high ground moves to the right). A closed
    /// line stays closed. Useful after mapping the points through a transform that flips
    /// orientation.
    pub fn reverse(&mut self) {
        self.points.reverse();
        self.edges.reverse();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn length_segments_and_reverse() {
        let mut p = Polyline {
            level: 1.0,
            points: vec![[0.0, 0.0], [3.0, 4.0], [3.0, 5.0]],
            edges: vec![[0, 1], [1, 2], [2, 3]],
            closed: false,
        };
        assert_eq!(p.segment_count(), 2);
        assert_eq!(p.length(), 6.0);
        p.reverse();
        assert_eq!(p.points()[0], [3.0, 5.0]);
        assert_eq!(p.edges()[0], [2, 3]);
    }
}
