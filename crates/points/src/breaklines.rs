//! The constrained Delaunay triangulation of the points and breaklines (spade): every
//! breakline segment is a chain of triangle edges, split where breaklines cross.
//!
//! Breakline vertices go on the points' lattice (rounded to the nearest lattice
//! position: at most half a lattice step from where the file puts them on each axis).
//! A line without heights takes them from the points' Delaunay triangulation, linearly
//! at its vertices; a line with heights (a 3D layer) keeps its own. A breakline vertex at
//! a point's position keeps the point's height (the points are what the TIN answers to).
//! Where two breaklines cross, spade splits both at the crossing; the new vertex, rounded
//! to the lattice, takes the height of the second line, linearly between its ends.

use spade::handles::FixedVertexHandle;
use spade::{
    ConstrainedDelaunayTriangulation, HasPosition, Point2, PositionInTriangulation, Triangulation,
};

use crate::cloud::{PointCloud, MAX_LATTICE};
use crate::delaunay::TriangulationError;

/// Why points and breaklines have no constrained triangulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BreaklineError {
    /// The points alone cannot be triangulated.
    #[error(transparent)]
    Points(#[from] TriangulationError),
    /// A breakline vertex lies outside the points' convex hull, where no point says what
    /// the surface is.
    #[error(
        "breakline {line} has a vertex at ({x}, {y}), outside the points' extent (their \
         convex hull)"
    )]
    Outside {
        /// The line, 1-based in file order.
        line: usize,
        /// World x of the vertex.
        x: f64,
        /// World y of the vertex.
        y: f64,
    },
    /// Breaklines cross at so fine an angle, or so close to other vertices, that the
    /// crossing rounded to the lattice folds a triangle over.
    #[error(
        "breaklines cross near ({x}, {y}) too close to other vertices for the points' \
         lattice (spacing {spacing}): the crossing cannot be placed on it"
    )]
    Crossing {
        /// World x of the crossing.
        x: f64,
        /// World y of the crossing.
        y: f64,
        /// The lattice spacing along x.
        spacing: f64,
    },
}

/// The constrained triangulation: triangles and constrained edges over the cloud's points
/// followed by the vertices the breaklines added.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ConstrainedTriangulation {
    /// Counter-clockwise triangles (x right, y up) as point indices, in spade's order.
    pub triangles: Vec<[u32; 3]>,
    /// The breakline segments as edges of `triangles` (split at points on them and at
    /// crossings), in spade's order.
    pub edges: Vec<[u32; 2]>,
    /// Points the cloud had before the breaklines' vertices were appended.
    pub points: usize,
    /// Vertices added where breaklines cross one another.
    pub crossings: usize,
}

#[derive(Debug, Clone, Copy)]
struct Site {
    position: Point2<f64>,
    index: u32,
    z: f64,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// A new vertex's index until it gets its place in the cloud.
const UNNUMBERED: u32 = u32::MAX;

/// Triangulates the cloud's (distinct) points with the `lines` (world `[x, y, z]`, `z`
/// used only when `has_z`) as constraints, appending the breaklines' vertices that are
/// not points to the cloud (lattice position and height). Deterministic.
///
/// # Errors
/// [`BreaklineError::Points`] for fewer than 3 points or all collinear;
/// [`BreaklineError::Outside`] for a breakline vertex outside the points' convex hull;
/// [`BreaklineError::Crossing`] when a crossing cannot be rounded to the lattice without
/// folding a triangle. The cloud is unchanged after an error.
///
/// # Panics
/// When two points share a position (call [`crate::dedupe`] first).
pub fn constrained_delaunay(
    cloud: &mut PointCloud,
    lines: &[Vec<[f64; 3]>],
    has_z: bool,
) -> Result<ConstrainedTriangulation, BreaklineError> {
    let n = cloud.xy.len();
    if n < 3 {
        return Err(TriangulationError::TooFewPoints(n).into());
    }
    let sites: Vec<Site> = (0..n)
        .map(|i| Site {
            position: Point2::new(cloud.xy[i][0] as f64, cloud.xy[i][1] as f64),
            index: i as u32,
            z: cloud.z[i],
        })
        .collect();
    let mut cdt: ConstrainedDelaunayTriangulation<Site> =
        ConstrainedDelaunayTriangulation::bulk_load(sites)
            .expect("lattice coordinates are in spade's range");
    assert_eq!(
        cdt.num_vertices(),
        n,
        "points share a position: dedupe first"
    );
    if cdt.num_inner_faces() == 0 {
        return Err(TriangulationError::Collinear(n).into());
    }

    // Every breakline vertex on the lattice with its height, from the points' Delaunay
    // triangulation (no breakline in it yet).
    let mut placed: Vec<Vec<([i64; 2], f64)>> = Vec::with_capacity(lines.len());
    for (l, line) in lines.iter().enumerate() {
        let mut out = Vec::with_capacity(line.len());
        for &[x, y, z] in line {
            let outside = BreaklineError::Outside { line: l + 1, x, y };
            let lx = ((x - cloud.origin[0]) / cloud.spacing[0]).round();
            let ly = ((y - cloud.origin[1]) / cloud.spacing[1]).round();
            let range = 0.0..=MAX_LATTICE as f64;
            if !(range.contains(&lx) && range.contains(&ly)) {
                return Err(outside);
            }
            let at = Point2::new(lx, ly);
            let Some(surface) = height_at(&cdt, at) else {
                return Err(outside);
            };
            out.push(([lx as i64, ly as i64], if has_z { z } else { surface }));
        }
        placed.push(out);
    }

    let mut added: Vec<([i64; 2], f64)> = Vec::new();
    let mut chains: Vec<Vec<FixedVertexHandle>> = Vec::with_capacity(placed.len());
    for line in &placed {
        let mut chain: Vec<FixedVertexHandle> = Vec::with_capacity(line.len());
        for &(p, z) in line {
            let at = Point2::new(p[0] as f64, p[1] as f64);
            let handle = match cdt.locate(at) {
                PositionInTriangulation::OnVertex(v) => v,
                _ => {
                    let index = (n + added.len()) as u32;
                    added.push((p, z));
                    cdt.insert(Site {
                        position: at,
                        index,
                        z,
                    })
                    .expect("lattice coordinates are in spade's range")
                }
            };
            if chain.last() != Some(&handle) {
                chain.push(handle);
            }
        }
        chains.push(chain);
    }
    for chain in &chains {
        for pair in chain.windows(2) {
            let a = *cdt.vertex(pair[0]).data();
            let b = *cdt.vertex(pair[1]).data();
            let (pa, pb, za, zb) = (a.position, b.position, a.z, b.z);
            cdt.add_constraint_and_split(pair[0], pair[1], |position| {
                let (dx, dy) = (pb.x - pa.x, pb.y - pa.y);
                let t = ((position.x - pa.x) * dx + (position.y - pa.y) * dy) / (dx * dx + dy * dy);
                Site {
                    position,
                    index: UNNUMBERED,
                    z: za + t.clamp(0.0, 1.0) * (zb - za),
                }
            });
        }
    }

    // Crossings onto the lattice, numbered after the breaklines' own vertices.
    let mut taken: std::collections::HashSet<[i64; 2]> = cloud.xy.iter().copied().collect();
    taken.extend(added.iter().map(|a| a.0));
    let fresh: Vec<FixedVertexHandle> = cdt
        .vertices()
        .filter(|v| v.data().index == UNNUMBERED)
        .map(|v| v.fix())
        .collect();
    let mut crossings: Vec<([i64; 2], f64)> = Vec::with_capacity(fresh.len());
    for handle in fresh {
        let site = cdt.vertex_data_mut(handle);
        let p = [
            site.position.x.round() as i64,
            site.position.y.round() as i64,
        ];
        let world = |s: &Site| {
            (
                cloud.origin[0] + cloud.spacing[0] * s.position.x,
                cloud.origin[1] + cloud.spacing[1] * s.position.y,
            )
        };
        if !taken.insert(p) {
            let (x, y) = world(site);
            return Err(BreaklineError::Crossing {
                x,
                y,
                spacing: cloud.spacing[0],
            });
        }
        site.index = (n + added.len() + crossings.len()) as u32;
        crossings.push((p, site.z));
    }
    let mut xy: Vec<[i64; 2]> = cloud.xy.clone();
    xy.extend(added.iter().chain(&crossings).map(|a| a.0));
    let triangles: Vec<[u32; 3]> = cdt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.data().index))
        .collect();
    for t in &triangles {
        let [a, b, c] = t.map(|i| xy[i as usize]);
        let det = i128::from(b[0] - a[0]) * i128::from(c[1] - a[1])
            - i128::from(b[1] - a[1]) * i128::from(c[0] - a[0]);
        if det <= 0 {
            let i = t.iter().copied().max().unwrap_or(0) as usize;
            return Err(BreaklineError::Crossing {
                x: cloud.origin[0] + cloud.spacing[0] * xy[i][0] as f64,
                y: cloud.origin[1] + cloud.spacing[1] * xy[i][1] as f64,
                spacing: cloud.spacing[0],
            });
        }
    }
    let edges: Vec<[u32; 2]> = cdt
        .undirected_edges()
        .filter(|e| e.is_constraint_edge())
        .map(|e| e.vertices().map(|v| v.data().index))
        .collect();
    cloud.xy = xy;
    cloud.z.extend(added.iter().chain(&crossings).map(|a| a.1));
    Ok(ConstrainedTriangulation {
        triangles,
        edges,
        points: n,
        crossings: crossings.len(),
    })
}

/// The triangulation's linear interpolation at `at`; `None` outside its convex hull.
fn height_at(cdt: &ConstrainedDelaunayTriangulation<Site>, at: Point2<f64>) -> Option<f64> {
    let face = match cdt.locate(at) {
        PositionInTriangulation::OnVertex(v) => return Some(cdt.vertex(v).data().z),
        PositionInTriangulation::OnFace(f) => cdt.face(f),
        PositionInTriangulation::OnEdge(e) => {
            let e = cdt.directed_edge(e);
            e.face().as_inner().or_else(|| e.rev().face().as_inner())?
        }
        _ => return None,
    };
    let w = face.barycentric_interpolation(at);
    let [a, b, c] = face.vertices().map(|v| v.data().z);
    Some(w[0] * a + w[1] * b + w[2] * c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::{ClassChoice, FileCrs};

    /// An 11 x 11 lattice of points 10 apart with z = x + 2y (world = lattice).
    fn grid_cloud() -> PointCloud {
        let mut xy = Vec::new();
        for y in 0..=10 {
            for x in 0..=10 {
                xy.push([x * 10 + 1, y * 10 + 1]);
            }
        }
        let z = xy.iter().map(|p| (p[0] + 2 * p[1]) as f64).collect();
        let n = xy.len();
        PointCloud {
            xy,
            z,
            origin: [0.0; 2],
            spacing: [1.0; 2],
            crs: FileCrs::default(),
            classes: ClassChoice::All,
            points_in_file: n as u64,
        }
    }

    fn has_chain(
        c: &ConstrainedTriangulation,
        cloud: &PointCloud,
        a: [i64; 2],
        b: [i64; 2],
    ) -> bool {
        // Walk constrained edges from a to b.
        let find = |p: [i64; 2]| cloud.xy.iter().position(|q| *q == p).map(|i| i as u32);
        let (Some(mut at), Some(end)) = (find(a), find(b)) else {
            return false;
        };
        let mut steps = 0;
        while at != end && steps < 1000 {
            let next = c.edges.iter().find_map(|&[u, v]| {
                let other = if u == at {
                    v
                } else if v == at {
                    u
                } else {
                    return None;
                };
                let q = cloud.xy[other as usize];
                let p = cloud.xy[at as usize];
                // Further along a -> b and on the line.
                let cross = (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]);
                let ahead = (b[0] - a[0]) * (q[0] - p[0]) + (b[1] - a[1]) * (q[1] - p[1]);
                (cross == 0 && ahead > 0).then_some(other)
            });
            let Some(next) = next else { return false };
            at = next;
            steps += 1;
        }
        at == end
    }

    #[test]
    fn two_d_lines_take_the_points_heights_and_are_kept_as_edges() {
        let mut cloud = grid_cloud();
        let line = vec![[5.0, 5.0, 999.0], [95.0, 55.0, 999.0], [95.0, 95.0, 999.0]];
        let c = constrained_delaunay(&mut cloud, &[line], false).unwrap();
        assert_eq!(c.points, 121);
        assert_eq!(cloud.xy.len(), 124);
        // z = x + 2y is linear: interpolated heights are exact.
        for i in 121..124 {
            let [x, y] = cloud.xy[i];
            assert!((cloud.z[i] - (x + 2 * y) as f64).abs() < 1e-9);
        }
        assert!(has_chain(&c, &cloud, [5, 5], [95, 55]));
        assert!(has_chain(&c, &cloud, [95, 55], [95, 95]));
        assert_eq!(c.crossings, 0);
    }

    #[test]
    fn three_d_lines_keep_their_heights_and_crossings_are_split() {
        let mut cloud = grid_cloud();
        let a = vec![[5.0, 50.0, 7.0], [95.0, 50.0, 7.0]];
        let b = vec![[50.0, 5.0, 1.0], [50.0, 95.0, 3.0]];
        let c = constrained_delaunay(&mut cloud, &[a, b], true).unwrap();
        assert_eq!(c.crossings, 1);
        let crossing = cloud.xy.iter().position(|p| *p == [50, 50]).unwrap();
        assert!(crossing >= 125);
        // The second line's height, halfway along it.
        assert_eq!(cloud.z[crossing], 2.0);
        let own = cloud.xy.iter().position(|p| *p == [5, 50]).unwrap();
        assert_eq!(cloud.z[own], 7.0);
        assert!(has_chain(&c, &cloud, [5, 50], [95, 50]));
        assert!(has_chain(&c, &cloud, [50, 5], [50, 95]));
        for t in &c.triangles {
            assert!(t.iter().all(|&i| (i as usize) < cloud.xy.len()));
        }
    }

    #[test]
    fn a_line_through_points_is_split_at_them() {
        let mut cloud = grid_cloud();
        // Along the row y = 31 through 11 points: no vertex added.
        let line = vec![[1.0, 31.0, 0.0], [101.0, 31.0, 0.0]];
        let c = constrained_delaunay(&mut cloud, &[line], false).unwrap();
        assert_eq!(cloud.xy.len(), 121);
        assert_eq!(c.edges.len(), 10);
    }

    #[test]
    fn a_vertex_outside_the_points_is_refused_and_the_cloud_kept() {
        let mut cloud = grid_cloud();
        let before = cloud.clone();
        let line = vec![[5.0, 5.0, 0.0], [150.0, 5.0, 0.0]];
        let e = constrained_delaunay(&mut cloud, &[line], false).unwrap_err();
        assert_eq!(
            e,
            BreaklineError::Outside {
                line: 1,
                x: 150.0,
                y: 5.0
            }
        );
        assert_eq!(cloud, before);
    }
}
