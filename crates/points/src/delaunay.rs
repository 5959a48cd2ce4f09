//! The Delaunay triangulation of the points (spade, exact predicates): its boundary is the
//! convex hull.
//!
//! The points are inserted one by one in the cloud's order, which [`crate::dedupe`] makes
//! the Z-order curve's, each located from the vertex inserted before it: a walk of a
//! step or two, over parts of the triangulation that are still in cache. spade's bulk
//! load (a circle sweep, points sorted by their distance from the centre) touches the
//! whole sweep front at every ring: on 20 M points it ran at 0.56 M points/s where this
//! order runs at 1.20 M (medians of 3; `examples/triangulation_rate.rs`, numbers in
//! `docs/results.md`, "Points").

use spade::{DelaunayTriangulation, LastUsedVertexHintGenerator, Point2, Triangulation};

use crate::cloud::PointCloud;

/// Why points have no triangulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TriangulationError {
    /// Fewer than three distinct positions.
    #[error("fewer than 3 distinct points ({0})")]
    TooFewPoints(usize),
    /// Every point on one line: no triangle has area.
    #[error("all {0} points are collinear")]
    Collinear(usize),
}

/// The Delaunay triangles of the cloud's (distinct) lattice positions, as point indices,
/// counter-clockwise (x right, y up), in spade's face order (deterministic for the same
/// points in the same order). Every point is a vertex. Lattice coordinates below 2^31 are
/// exact in `f64`.
///
/// # Errors
/// [`TriangulationError`] for fewer than 3 points or all collinear.
///
/// # Panics
/// When two points share a position (call [`crate::dedupe`] first).
pub fn delaunay(cloud: &PointCloud) -> Result<Vec<[u32; 3]>, TriangulationError> {
    let n = cloud.xy.len();
    if n < 3 {
        return Err(TriangulationError::TooFewPoints(n));
    }
    // spade numbers vertices in insertion order: vertex `i` is point `i` (no duplicates).
    let sites = cloud
        .xy
        .iter()
        .map(|p| Point2::new(p[0] as f64, p[1] as f64));
    let triangulation: DelaunayTriangulation<Point2<f64>, (), (), (), LastUsedVertexHintGenerator> =
        insert_in_order(n, sites);
    assert_eq!(
        triangulation.num_vertices(),
        n,
        "points share a position: dedupe first"
    );
    let triangles: Vec<[u32; 3]> = triangulation
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    if triangles.is_empty() {
        return Err(TriangulationError::Collinear(n));
    }
    Ok(triangles)
}

/// A triangulation of `sites` (`n` of them) inserted one by one in the order given, each
/// located from the vertex inserted before it: fast when neighbours in the order are
/// neighbours in the plane (see the module's note).
///
/// # Panics
/// On a coordinate beyond spade's range (lattice coordinates are below 2^31).
pub(crate) fn insert_in_order<T: Triangulation>(
    n: usize,
    sites: impl Iterator<Item = T::Vertex>,
) -> T {
    let mut triangulation = T::with_capacity(n, 3 * n, 2 * n);
    for site in sites {
        triangulation
            .insert(site)
            .expect("lattice coordinates are in spade's range");
    }
    triangulation
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::{ClassChoice, FileCrs};

    fn cloud(xy: Vec<[i64; 2]>) -> PointCloud {
        let n = xy.len();
        PointCloud {
            xy,
            z: vec![0.0; n],
            origin: [0.0; 2],
            spacing: [1.0; 2],
            crs: FileCrs::default(),
            classes: ClassChoice::All,
            points_in_file: n as u64,
        }
    }

    #[test]
    fn a_square_with_its_centre_gives_four_triangles() {
        let t = delaunay(&cloud(vec![[0, 0], [2, 0], [0, 2], [2, 2], [1, 1]])).unwrap();
        assert_eq!(t.len(), 4);
        for [a, b, c] in t {
            assert!(a != b && b != c && a != c);
        }
    }

    #[test]
    fn degenerate_inputs_are_refused() {
        assert_eq!(
            delaunay(&cloud(vec![[0, 0], [1, 1]])),
            Err(TriangulationError::TooFewPoints(2))
        );
        assert_eq!(
            delaunay(&cloud(vec![[0, 0], [1, 1], [2, 2], [5, 5]])),
            Err(TriangulationError::Collinear(4))
        );
    }
}
