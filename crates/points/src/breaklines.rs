//! The constrained Delaunay triangulation of the points, breaklines and a boundary
//! (spade): every breakline and boundary segment is a chain of triangle edges, split where
//! breaklines cross; triangles outside the boundary, or eroded from the outside by a
//! largest edge length (a concave hull), are removed with the points only they held.
//!
//! Breakline vertices go on the points' lattice (rounded to the nearest lattice
//! position: at most half a lattice step from where the file puts them on each axis).
//! A line without heights takes them from the points' Delaunay triangulation, linearly
//! at its vertices; a line with heights (a 3D layer) keeps its own. A breakline vertex at
//! a point's position keeps the point's height (the points are what the TIN answers to).
//! Where two breaklines cross, spade splits both at the crossing; the new vertex, rounded
//! to the lattice, takes the height of the second line, linearly between its ends. When
//! a rounded crossing lands on another vertex or folds a triangle (on a raster's samples,
//! every lattice position is one), the lattice is refined by up to 1024 (a power of two,
//! the same positions) and the triangulation made again.
//!
//! A boundary's rings (outline and holes, even-odd) take heights the same way and must
//! lie within the points' convex hull; no breakline may cross them (a crossing would move
//! the outline by the lattice rounding). A triangle is inside when its centroid is, by an
//! exact integer test: the rings are chains of its edges, so no triangle straddles them.

use spade::handles::FixedVertexHandle;
use spade::{
    ConstrainedDelaunayTriangulation, HasPosition, Point2, PositionInTriangulation, Triangulation,
};

use crate::cloud::{PointCloud, MAX_LATTICE};
use crate::delaunay::{insert_in_order, TriangulationError};

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
    /// A boundary ring's vertex lies outside the points' convex hull.
    #[error(
        "boundary ring {ring} has a vertex at ({x}, {y}), outside the points' extent (their \
         convex hull)"
    )]
    BoundaryOutside {
        /// The ring, 1-based in file order.
        ring: usize,
        /// World x of the vertex.
        x: f64,
        /// World y of the vertex.
        y: f64,
    },
    /// A breakline crosses the boundary (or a boundary ring crosses another).
    #[error("a breakline or another ring crosses boundary ring {ring}")]
    BoundaryCrossed {
        /// The ring, 1-based in file order.
        ring: usize,
    },
    /// No point is left inside the boundary (and the edge length limit).
    #[error("none of the points is inside the boundary or the --hull-edge-length hull")]
    Empty,
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
    /// The cloud's points kept (the first ones of the cloud, in their order), before the
    /// breaklines' and boundary's vertices that follow them.
    pub points: usize,
    /// The vertices the lines and rings were given with (as point indices, sorted): the
    /// decimation keeps them, so every segment of the file stays a chain of edges between
    /// its own two ends.
    pub line_vertices: Vec<u32>,
    /// The cloud's points removed: outside the boundary, or only in triangles the edge
    /// length limit removed.
    pub dropped: usize,
    /// Vertices added where breaklines cross one another.
    pub crossings: usize,
}

/// What constrains the triangulation besides the points.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[non_exhaustive]
pub struct Constraints<'a> {
    /// Lines kept as edges, world `[x, y, z]`.
    pub breaklines: &'a [Vec<[f64; 3]>],
    /// Whether the breaklines' `z` are heights (else they take the points').
    pub breaklines_have_z: bool,
    /// The boundary's closed rings (outline and holes), world `[x, y, z]`; empty: none.
    pub boundary: &'a [Vec<[f64; 3]>],
    /// Whether the rings' `z` are heights.
    pub boundary_has_z: bool,
    /// Remove triangles from the outside in while an outer edge is longer than this
    /// (world units), except constrained edges: a concave hull.
    pub max_edge_length: Option<f64>,
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

/// A line's vertex on the lattice, with its height.
type Placed = ([i64; 2], f64);

/// A new vertex's index until it gets its place in the cloud.
const UNNUMBERED: u32 = u32::MAX;

/// Triangulates the cloud's (distinct) points with the breaklines and boundary rings of
/// `constraints` as constrained edges, keeps the triangles inside the boundary and the
/// edge length limit, and rewrites the cloud: the points kept, in their order, then the
/// breaklines' and rings' vertices that are not points (lattice position and height).
/// Deterministic.
///
/// # Errors
/// [`BreaklineError::Points`] for fewer than 3 points or all collinear;
/// [`BreaklineError::Outside`], [`BreaklineError::BoundaryOutside`] for a vertex outside
/// the points' convex hull; [`BreaklineError::BoundaryCrossed`] for a breakline crossing
/// the boundary; [`BreaklineError::Crossing`] when a crossing cannot be rounded to the
/// lattice without folding a triangle; [`BreaklineError::Empty`] when no triangle is left.
/// The cloud is unchanged after an error.
///
/// # Panics
/// When two points share a position (call [`crate::dedupe`] first).
pub fn constrained_delaunay(
    cloud: &mut PointCloud,
    constraints: &Constraints<'_>,
) -> Result<ConstrainedTriangulation, BreaklineError> {
    let mut work = cloud.clone();
    let result = match triangulate(&mut work, constraints) {
        Err(BreaklineError::Crossing { .. }) if refine(&mut work) => {
            triangulate(&mut work, constraints)?
        }
        other => other?,
    };
    *cloud = work;
    Ok(result)
}

/// The finest refinement of the lattice tried when a crossing falls on a vertex.
const MAX_REFINEMENT: i64 = 1024;

/// Refines the cloud's lattice by the largest power of two up to [`MAX_REFINEMENT`]
/// that keeps every coordinate within `MAX_LATTICE` (the same positions on a finer
/// lattice: every orientation keeps its sign); false when none does.
fn refine(cloud: &mut PointCloud) -> bool {
    let largest = cloud
        .xy
        .iter()
        .map(|p| p[0].max(p[1]))
        .max()
        .unwrap_or(0)
        .max(1);
    let mut factor = MAX_REFINEMENT;
    while factor > 1 && largest.saturating_mul(factor) > MAX_LATTICE {
        factor /= 2;
    }
    if factor == 1 {
        return false;
    }
    for p in &mut cloud.xy {
        *p = p.map(|v| v * factor);
    }
    cloud.spacing = cloud.spacing.map(|s| s / factor as f64);
    true
}

/// [`constrained_delaunay`] on the cloud's lattice as it is.
fn triangulate(
    cloud: &mut PointCloud,
    constraints: &Constraints<'_>,
) -> Result<ConstrainedTriangulation, BreaklineError> {
    let lines = constraints.breaklines;
    let has_z = constraints.breaklines_have_z;
    let n = cloud.xy.len();
    if n < 3 {
        return Err(TriangulationError::TooFewPoints(n).into());
    }
    let sites = (0..n).map(|i| Site {
        position: Point2::new(cloud.xy[i][0] as f64, cloud.xy[i][1] as f64),
        index: i as u32,
        z: cloud.z[i],
    });
    // In the cloud's Z-order, as the Delaunay triangulation without lines.
    let mut cdt: ConstrainedDelaunayTriangulation<Site> = insert_in_order(n, sites);
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
    let rings = place(
        cloud,
        &cdt,
        constraints.boundary,
        constraints.boundary_has_z,
        |ring, x, y| BreaklineError::BoundaryOutside { ring, x, y },
    )?;
    let placed = place(cloud, &cdt, lines, has_z, |line, x, y| {
        BreaklineError::Outside { line, x, y }
    })?;

    let mut added: Vec<Placed> = Vec::new();
    let mut chains: Vec<Vec<FixedVertexHandle>> = Vec::with_capacity(placed.len());
    for line in rings.iter().chain(&placed) {
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
    let (ring_chains, line_chains) = chains.split_at(rings.len());
    for chain in line_chains {
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

    // The rings last, refused where they cross a breakline or one another.
    for (r, chain) in ring_chains.iter().enumerate() {
        for pair in chain.windows(2) {
            if cdt.try_add_constraint(pair[0], pair[1]).is_empty() {
                return Err(BreaklineError::BoundaryCrossed { ring: r + 1 });
            }
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
    let mut crossings: Vec<Placed> = Vec::with_capacity(fresh.len());
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
    let line_vertices: Vec<u32> = chains
        .iter()
        .flatten()
        .map(|&h| cdt.vertex(h).data().index)
        .collect();
    let mut z = cloud.z.clone();
    z.extend(added.iter().chain(&crossings).map(|a| a.1));

    let ring_positions: Vec<Vec<[i64; 2]>> = rings
        .iter()
        .map(|r| r.iter().map(|p| p.0).collect())
        .collect();
    let mut keep: Vec<bool> = triangles
        .iter()
        .map(|t| {
            ring_positions.is_empty() || centroid_inside(t.map(|i| xy[i as usize]), &ring_positions)
        })
        .collect();
    if let Some(limit) = constraints.max_edge_length {
        erode(&triangles, &mut keep, &edges, |a, b| {
            let [p, q] = [xy[a as usize], xy[b as usize]];
            let dx = (q[0] - p[0]) as f64 * cloud.spacing[0];
            let dy = (q[1] - p[1]) as f64 * cloud.spacing[1];
            dx.hypot(dy) > limit
        });
    }
    if !keep.iter().any(|&k| k) {
        return Err(BreaklineError::Empty);
    }

    // Only the vertices of kept triangles stay, in their order.
    let kept: Vec<[u32; 3]> = triangles
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(t, _)| *t)
        .collect();
    let mut used = vec![false; xy.len()];
    for t in &kept {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut renumber = vec![UNNUMBERED; xy.len()];
    let mut next = 0u32;
    for (v, &u) in used.iter().enumerate() {
        if u {
            renumber[v] = next;
            next += 1;
        }
    }
    let kept_edges: std::collections::HashSet<(u32, u32)> = kept
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    let edges: Vec<[u32; 2]> = edges
        .into_iter()
        .filter(|&[a, b]| kept_edges.contains(&(a, b)) || kept_edges.contains(&(b, a)))
        .map(|e| e.map(|v| renumber[v as usize]))
        .collect();
    let triangles: Vec<[u32; 3]> = kept
        .iter()
        .map(|t| t.map(|v| renumber[v as usize]))
        .collect();
    let mut line_vertices: Vec<u32> = line_vertices
        .into_iter()
        .filter(|&v| used[v as usize])
        .map(|v| renumber[v as usize])
        .collect();
    line_vertices.sort_unstable();
    line_vertices.dedup();
    let points = used[..n].iter().filter(|&&u| u).count();
    if points == 0 {
        return Err(BreaklineError::Empty);
    }
    cloud.xy = xy
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(p, _)| *p)
        .collect();
    cloud.z = z
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(h, _)| *h)
        .collect();
    Ok(ConstrainedTriangulation {
        triangles,
        edges,
        points,
        line_vertices,
        dropped: n - points,
        crossings: crossings.len(),
    })
}

/// The vertices of `lines` on the cloud's lattice with their heights (their own when
/// `has_z`, else the points' triangulation's); `outside(line, x, y)` for a vertex outside
/// the points' convex hull.
fn place(
    cloud: &PointCloud,
    cdt: &ConstrainedDelaunayTriangulation<Site>,
    lines: &[Vec<[f64; 3]>],
    has_z: bool,
    outside: impl Fn(usize, f64, f64) -> BreaklineError,
) -> Result<Vec<Vec<Placed>>, BreaklineError> {
    let mut placed = Vec::with_capacity(lines.len());
    for (l, line) in lines.iter().enumerate() {
        let mut out = Vec::with_capacity(line.len());
        for &[x, y, z] in line {
            let lx = ((x - cloud.origin[0]) / cloud.spacing[0]).round();
            let ly = ((y - cloud.origin[1]) / cloud.spacing[1]).round();
            let range = 0.0..=MAX_LATTICE as f64;
            if !(range.contains(&lx) && range.contains(&ly)) {
                return Err(outside(l + 1, x, y));
            }
            let Some(surface) = height_at(cdt, Point2::new(lx, ly)) else {
                return Err(outside(l + 1, x, y));
            };
            out.push(([lx as i64, ly as i64], if has_z { z } else { surface }));
        }
        placed.push(out);
    }
    Ok(placed)
}

/// Whether the centroid of the triangle `t` is inside the rings (even-odd), exactly:
/// coordinates tripled so the centroid is an integer point. The rings are chains of
/// triangle edges, so the centroid is never on one.
fn centroid_inside(t: [[i64; 2]; 3], rings: &[Vec<[i64; 2]>]) -> bool {
    let c = [
        i128::from(t[0][0] + t[1][0] + t[2][0]),
        i128::from(t[0][1] + t[1][1] + t[2][1]),
    ];
    let mut inside = false;
    for ring in rings {
        for w in ring.windows(2) {
            let p = [i128::from(w[0][0]) * 3, i128::from(w[0][1]) * 3];
            let q = [i128::from(w[1][0]) * 3, i128::from(w[1][1]) * 3];
            if (p[1] > c[1]) != (q[1] > c[1]) {
                // Whether the edge passes right of the centroid, without dividing.
                let side = (q[0] - p[0]) * (c[1] - p[1]) - (c[0] - p[0]) * (q[1] - p[1]);
                if (side > 0) == (q[1] > p[1]) {
                    inside = !inside;
                }
            }
        }
    }
    inside
}

/// Removes kept triangles from the outside in while one has an outer edge (no kept
/// triangle across it) for which `too_long` holds and that is not in `constrained`. The
/// result is the largest set with no such triangle, whatever the order.
fn erode(
    triangles: &[[u32; 3]],
    keep: &mut [bool],
    constrained: &[[u32; 2]],
    too_long: impl Fn(u32, u32) -> bool,
) {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let fixed: std::collections::HashSet<(u32, u32)> =
        constrained.iter().map(|&[a, b]| key(a, b)).collect();
    let mut across: std::collections::HashMap<(u32, u32), Vec<usize>> =
        std::collections::HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            across.entry(key(t[e], t[(e + 1) % 3])).or_default().push(i);
        }
    }
    let outer = |keep: &[bool], i: usize, a: u32, b: u32| {
        across[&key(a, b)].iter().all(|&j| j == i || !keep[j])
    };
    let mut queue: std::collections::VecDeque<usize> = (0..triangles.len()).collect();
    while let Some(i) = queue.pop_front() {
        if !keep[i] {
            continue;
        }
        let t = triangles[i];
        let remove = (0..3).any(|e| {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            !fixed.contains(&key(a, b)) && outer(keep, i, a, b) && too_long(a, b)
        });
        if remove {
            keep[i] = false;
            for e in 0..3 {
                for &j in &across[&key(t[e], t[(e + 1) % 3])] {
                    if j != i && keep[j] {
                        queue.push_back(j);
                    }
                }
            }
        }
    }
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

    fn lines(lines: &[Vec<[f64; 3]>], has_z: bool) -> Constraints<'_> {
        Constraints {
            breaklines: lines,
            breaklines_have_z: has_z,
            ..Constraints::default()
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
        let c = constrained_delaunay(&mut cloud, &lines(&[line], false)).unwrap();
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
        let c = constrained_delaunay(&mut cloud, &lines(&[a, b], true)).unwrap();
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
    fn a_crossing_on_a_point_refines_the_lattice() {
        // Every lattice position 0..=10 is a point: the crossing at (4.5, 4.5) rounds onto
        // one, so the lattice is refined (by 1024) and the crossing placed exactly.
        let mut xy = Vec::new();
        for y in 0..=10 {
            for x in 0..=10 {
                xy.push([x, y]);
            }
        }
        let n = xy.len();
        let mut cloud = PointCloud {
            z: xy.iter().map(|p| (p[0] + p[1]) as f64).collect(),
            xy,
            origin: [0.0; 2],
            spacing: [1.0; 2],
            crs: FileCrs::default(),
            classes: ClassChoice::All,
            points_in_file: n as u64,
        };
        let a = vec![[0.0, 0.0, 0.0], [9.0, 9.0, 0.0]];
        let b = vec![[0.0, 9.0, 0.0], [9.0, 0.0, 0.0]];
        let c = constrained_delaunay(&mut cloud, &lines(&[a, b], false)).unwrap();
        assert_eq!(cloud.spacing, [1.0 / 1024.0; 2]);
        assert_eq!(c.crossings, 1);
        assert_eq!(cloud.xy[0], [0, 0]);
        assert!(cloud.xy.contains(&[4608, 4608]));
        assert!(has_chain(&c, &cloud, [0, 0], [9216, 9216]));
        assert!(has_chain(&c, &cloud, [0, 9216], [9216, 0]));
    }

    #[test]
    fn a_line_through_points_is_split_at_them() {
        let mut cloud = grid_cloud();
        // Along the row y = 31 through 11 points: no vertex added.
        let line = vec![[1.0, 31.0, 0.0], [101.0, 31.0, 0.0]];
        let c = constrained_delaunay(&mut cloud, &lines(&[line], false)).unwrap();
        assert_eq!(cloud.xy.len(), 121);
        assert_eq!(c.edges.len(), 10);
    }

    fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 3]> {
        vec![
            [x0, y0, 0.0],
            [x1, y0, 0.0],
            [x1, y1, 0.0],
            [x0, y1, 0.0],
            [x0, y0, 0.0],
        ]
    }

    #[test]
    fn a_boundary_with_a_hole_keeps_the_points_inside_and_its_rings_as_edges() {
        let mut cloud = grid_cloud();
        let rings = [square(5.0, 5.0, 75.0, 75.0), square(35.0, 35.0, 55.0, 55.0)];
        let c = constrained_delaunay(
            &mut cloud,
            &Constraints {
                boundary: &rings,
                ..Constraints::default()
            },
        )
        .unwrap();
        // Inside the outline: x, y in 11..=71 (7 x 7 = 49); in the hole: 41, 51 (4).
        assert_eq!(c.points, 45);
        assert_eq!(c.dropped, 121 - 45);
        assert_eq!(cloud.xy.len(), 45 + 8);
        for p in &cloud.xy[..45] {
            let inside = |v: i64, lo, hi| v >= lo && v <= hi;
            assert!(inside(p[0], 5, 75) && inside(p[1], 5, 75));
            assert!(!(inside(p[0], 35, 55) && inside(p[1], 35, 55)));
        }
        assert!(has_chain(&c, &cloud, [5, 5], [75, 5]));
        assert!(has_chain(&c, &cloud, [35, 55], [35, 35]));
        // The triangles tile the square less the hole: area 70^2 - 20^2, doubled.
        let area: i64 = c
            .triangles
            .iter()
            .map(|t| {
                let [a, b, d] = t.map(|i| cloud.xy[i as usize]);
                (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0])
            })
            .sum();
        assert_eq!(area, 2 * (70 * 70 - 20 * 20));
    }

    fn only_rings<'a>(rings: &'a [Vec<[f64; 3]>], lines: &'a [Vec<[f64; 3]>]) -> Constraints<'a> {
        Constraints {
            boundary: rings,
            breaklines: lines,
            ..Constraints::default()
        }
    }

    #[test]
    fn bad_boundaries_are_refused() {
        let mut cloud = grid_cloud();
        let before = cloud.clone();
        // Between the points: no point inside.
        let empty = [square(12.0, 12.0, 18.0, 18.0)];
        let only = only_rings;
        let mut c = cloud.clone();
        let e = constrained_delaunay(&mut c, &only(&empty, &[]));
        assert_eq!(e, Err(BreaklineError::Empty));
        let crossing = [vec![[2.0, 50.0, 0.0], [98.0, 50.0, 0.0]]];
        let e = constrained_delaunay(
            &mut cloud,
            &only(&[square(5.0, 5.0, 75.0, 75.0)], &crossing),
        );
        assert_eq!(e, Err(BreaklineError::BoundaryCrossed { ring: 1 }));
        assert_eq!(cloud, before);
        let e = constrained_delaunay(&mut cloud, &only(&[square(-5.0, 5.0, 75.0, 75.0)], &[]));
        assert!(matches!(
            e,
            Err(BreaklineError::BoundaryOutside { ring: 1, .. })
        ));
    }

    #[test]
    fn a_longest_edge_erodes_a_concave_hull() {
        // An L of lattice points: the Delaunay triangulation fills the notch with long
        // triangles, which an edge length of 15 removes.
        let mut cloud = grid_cloud();
        let keep: Vec<usize> = (0..cloud.xy.len())
            .filter(|&i| cloud.xy[i][0] <= 41 || cloud.xy[i][1] <= 41)
            .collect();
        cloud.xy = keep.iter().map(|&i| cloud.xy[i]).collect();
        cloud.z = keep.iter().map(|&i| cloud.z[i]).collect();
        let n = cloud.xy.len();
        let mut full = cloud.clone();
        let all = constrained_delaunay(&mut full, &Constraints::default()).unwrap();
        let c = constrained_delaunay(
            &mut cloud,
            &Constraints {
                max_edge_length: Some(15.0),
                ..Constraints::default()
            },
        )
        .unwrap();
        assert_eq!((c.points, c.dropped), (n, 0));
        // The L's cells, two triangles each (4 x 10 + 6 x 4), and the half cell at its
        // inner corner, whose outer edge (a cell's diagonal, 14.1) is short enough.
        assert_eq!(c.triangles.len(), 2 * (40 + 24) + 1);
        assert!(all.triangles.len() > c.triangles.len());
        // Nothing is that short: every triangle goes, and so every point.
        let e = constrained_delaunay(
            &mut cloud,
            &Constraints {
                max_edge_length: Some(5.0),
                ..Constraints::default()
            },
        );
        assert_eq!(e, Err(BreaklineError::Empty));
    }

    #[test]
    fn a_vertex_outside_the_points_is_refused_and_the_cloud_kept() {
        let mut cloud = grid_cloud();
        let before = cloud.clone();
        let line = vec![[5.0, 5.0, 0.0], [150.0, 5.0, 0.0]];
        let e = constrained_delaunay(&mut cloud, &lines(&[line], false)).unwrap_err();
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
