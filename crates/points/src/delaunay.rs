//! The Delaunay triangulation of the points (spade, bulk loaded, exact predicates): its
//! boundary is the convex hull.

use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

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

struct Site {
    position: Point2<f64>,
    index: u32,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// The Delaunay triangles of the cloud's (distinct) lattice positions, as point indices,
/// counter-clockwise (x right, y up), in spade's face order (deterministic for the same
/// points). Every point is a vertex. Lattice coordinates below 2^31 are exact in `f64`.
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
    let sites = cloud
        .xy
        .iter()
        .enumerate()
        .map(|(i, p)| Site {
            position: Point2::new(p[0] as f64, p[1] as f64),
            index: i as u32,
        })
        .collect();
    let triangulation: DelaunayTriangulation<Site> =
        DelaunayTriangulation::bulk_load(sites).expect("lattice coordinates are in spade's range");
    assert_eq!(
        triangulation.num_vertices(),
        n,
        "points share a position: dedupe first"
    );
    let triangles: Vec<[u32; 3]> = triangulation
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.data().index))
        .collect();
    if triangles.is_empty() {
        return Err(TriangulationError::Collinear(n));
    }
    Ok(triangles)
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
