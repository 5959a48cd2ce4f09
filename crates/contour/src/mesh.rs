//! The triangle mesh to contour: vertices, triangles and the edge adjacency between them.

use crate::{Error, Result};

/// No triangle across this edge: it is on the domain's boundary (outline or nodata hole).
pub(crate) const NONE: u32 = u32::MAX;

/// A validated triangle mesh with heights, ready to contour.
///
/// Vertices are `[x, y, z]`: a position in the plane and the height there. Triangle `t`'s
/// local edge `k` (for `k` in `0..3`) joins its corners `k` and `(k + 1) % 3`; the mesh
/// stores, for every such edge, the edge of the other triangle that shares it (its
/// *twin*), found from the triangle list alone: two triangles are neighbours exactly when
/// they share both vertex indices of an edge. An edge used by one triangle is a *boundary*
/// edge, on the outline of the domain or of a nodata hole.
///
/// # Guarantees
/// Every triangle names three distinct existing vertices with finite coordinates and
/// heights, and every edge is shared by at most two triangles. Orientation may vary from
/// triangle to triangle; contouring reads each triangle's orientation from its
/// coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ContourMesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// `twins[3 t + k]`: the half-edge `3 t' + k'` across triangle `t`'s edge `k`, or
    /// [`NONE`].
    twins: Vec<u32>,
    /// Lowest and highest height of the vertices the triangles use.
    height_range: Option<(f64, f64)>,
}

/// `range` widened to take in `z`.
fn widen(range: Option<(f64, f64)>, z: f64) -> Option<(f64, f64)> {
    Some(match range {
        None => (z, z),
        Some((lo, hi)) => (lo.min(z), hi.max(z)),
    })
}

impl ContourMesh {
    /// Checks the mesh and builds its edge adjacency.
    ///
    /// Vertices no triangle uses are allowed and ignored (their values may be NaN).
    ///
    /// # Errors
    /// [`Error::VertexOutOfRange`], [`Error::RepeatedVertex`], [`Error::NonFiniteVertex`],
    /// [`Error::NonManifoldEdge`], [`Error::TooManyTriangles`].
    ///
    /// # Runtime
    /// Linear in the number of vertices and triangles (edges are bucketed by their smaller
    /// vertex, so no global sort and no hash map: the result never depends on hashing).
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<ContourMesh> {
        let max = (NONE / 3) as usize;
        if triangles.len() > max {
            return Err(Error::TooManyTriangles {
                triangles: triangles.len(),
                max,
            });
        }
        let mut height_range = None;
        for (t, tri) in triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                let Some(p) = vertices.get(v as usize) else {
                    return Err(Error::VertexOutOfRange {
                        triangle: t,
                        vertex: v,
                        vertices: vertices.len(),
                    });
                };
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(Error::NonFiniteVertex { vertex: v });
                }
                if tri[(k + 1) % 3] == v {
                    return Err(Error::RepeatedVertex {
                        triangle: t,
                        vertex: v,
                    });
                }
                height_range = widen(height_range, p[2]);
            }
        }
        let twins = build_twins(vertices.len(), &triangles)?;
        Ok(ContourMesh {
            vertices,
            triangles,
            twins,
            height_range,
        })
    }

    /// The full-resolution mesh of a grid: two triangles per cell whose four corners are
    /// finite, split along the cell's `(x, y)`–`(x + 1, y + 1)` diagonal, as
    /// `tinsmith-core` builds its initial mesh.
    ///
    /// Vertex `y * width + x` is sample `(x, y)` at position `(x, y)` (column, row) with the
    /// sample's value as height; triangles are `(a, b, c)` and `(a, c, d)` for the cell
    /// corners `a = (x, y)`, `b = (x + 1, y)`, `c = (x + 1, y + 1)`, `d = (x, y + 1)`, in
    /// row-major cell order. Non-finite samples are nodata: cells touching them are left
    /// out, so contours end at their edge.
    ///
    /// # Errors
    /// [`Error::GridSize`] when `values.len() != width * height` or the grid has 2^32
    /// samples or more; [`Error::TooManyTriangles`].
    pub fn from_grid(width: u32, height: u32, values: &[f64]) -> Result<ContourMesh> {
        let n = width as usize * height as usize;
        if values.len() != n || n as u64 >= NONE as u64 {
            return Err(Error::GridSize {
                width,
                height,
                expected: n,
                actual: values.len(),
            });
        }
        let (w, h) = (width as usize, height as usize);
        let vertices: Vec<[f64; 3]> = values
            .iter()
            .enumerate()
            .map(|(i, &z)| [(i % w) as f64, (i / w) as f64, z])
            .collect();
        let (cw, ch) = (w.saturating_sub(1), h.saturating_sub(1));
        let max = (NONE / 3) as usize;
        // Whether the cell whose top-left sample is `a` has four finite corners.
        let valid = |a: usize| {
            [a, a + 1, a + w + 1, a + w]
                .iter()
                .all(|&j| values[j].is_finite())
        };
        let valid_cells = (0..ch * cw)
            .filter(|&i| valid((i / cw) * w + i % cw))
            .count();
        if 2 * valid_cells > max {
            return Err(Error::TooManyTriangles {
                triangles: 2 * valid_cells,
                max,
            });
        }
        // `first[cell]`: the cell's first triangle (the second follows it), or NONE.
        let mut first = vec![NONE; cw * ch];
        let mut triangles = Vec::with_capacity(2 * valid_cells);
        let mut height_range = None;
        for y in 0..ch {
            for x in 0..cw {
                let a = y * w + x;
                let (b, c, d) = (a + 1, a + w + 1, a + w);
                if valid(a) {
                    // In the order `height_range` of `new` would meet them (the sign a
                    // zero range end gets depends on it).
                    for i in [a, b, c, a, c, d] {
                        height_range = widen(height_range, values[i]);
                    }
                    first[y * cw + x] = triangles.len() as u32;
                    let [a, b, c, d] = [a, b, c, d].map(|i| i as u32);
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        let twins = grid_twins(cw, ch, &first, triangles.len());
        debug_assert!(
            build_twins(vertices.len(), &triangles).is_ok_and(|general| general == twins),
            "the grid's twins are those of any mesh"
        );
        Ok(ContourMesh {
            vertices,
            triangles,
            twins,
            height_range,
        })
    }

    /// The vertices, `[x, y, z]`.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The triangles, as indices into [`ContourMesh::vertices`].
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Lowest and highest height of the vertices the triangles use, or `None` without
    /// triangles.
    pub fn height_range(&self) -> Option<(f64, f64)> {
        self.height_range
    }

    /// How many line segments contouring at `levels` (sorted ascending) makes, at most:
    /// per triangle, the levels above its lowest corner and up to its highest (a corner
    /// at a level counts as above it, as [`crate::contour`] has it). Cheap, for sizing the
    /// output before making it.
    pub fn segment_count(&self, levels: &[f64]) -> u64 {
        // The levels at or below each vertex (`partition_point` is monotone in the height,
        // so a triangle's lowest and highest corners give its least and greatest counts).
        let at_or_below: Vec<u32> = self
            .vertices
            .iter()
            .map(|v| levels.partition_point(|&l| l <= v[2]) as u32)
            .collect();
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| at_or_below[v as usize]);
                u64::from(a.max(b).max(c) - a.min(b).min(c))
            })
            .sum()
    }

    /// Number of triangles using the edge between vertices `a` and `b` (0, 1 or 2).
    pub fn edge_triangle_count(&self, a: u32, b: u32) -> usize {
        let mut count = 0;
        for tri in &self.triangles {
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                if (p, q) == (a, b) || (p, q) == (b, a) {
                    count += 1;
                }
            }
        }
        count
    }

    /// The half-edge across half-edge `h` (`3 t + k`), or [`NONE`].
    pub(crate) fn twin(&self, h: u32) -> u32 {
        self.twins[h as usize]
    }
}

/// The twin half-edges of [`ContourMesh::from_grid`]'s mesh, read off the grid: `first`
/// holds each of the `cw x ch` cells' first triangle `(a, b, c)` (its second, `(a, c, d)`,
/// follows) or [`NONE`]. The same twins [`build_twins`] finds, without bucketing.
fn grid_twins(cw: usize, ch: usize, first: &[u32], triangles: usize) -> Vec<u32> {
    let mut twins = vec![NONE; 3 * triangles];
    let cell = |x: usize, y: usize| first[y * cw + x];
    for y in 0..ch {
        for x in 0..cw {
            let lower = cell(x, y);
            if lower == NONE {
                continue;
            }
            let upper = lower + 1;
            let (l, u) = (3 * lower as usize, 3 * upper as usize);
            // (a, b, c): top edge a-b, right edge b-c, diagonal c-a.
            if y > 0 && cell(x, y - 1) != NONE {
                twins[l] = 3 * (cell(x, y - 1) + 1) + 1;
            }
            if x + 1 < cw && cell(x + 1, y) != NONE {
                twins[l + 1] = 3 * (cell(x + 1, y) + 1) + 2;
            }
            twins[l + 2] = 3 * upper;
            // (a, c, d): diagonal a-c, bottom edge c-d, left edge d-a.
            twins[u] = 3 * lower + 2;
            if y + 1 < ch && cell(x, y + 1) != NONE {
                twins[u + 1] = 3 * cell(x, y + 1);
            }
            if x > 0 && cell(x - 1, y) != NONE {
                twins[u + 2] = 3 * cell(x - 1, y) + 1;
            }
        }
    }
    twins
}

/// Twin half-edges from the triangle list, in linear time: half-edges are bucketed by their
/// smaller vertex (a counting sort), then matched by their larger vertex within each small
/// bucket, in half-edge order, so the result is deterministic.
fn build_twins(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<Vec<u32>> {
    let halves = triangles.len() * 3;
    let ends = |h: usize| {
        let tri = &triangles[h / 3];
        let (p, q) = (tri[h % 3], tri[(h + 1) % 3]);
        (p.min(q), p.max(q))
    };
    let mut start = vec![0u32; vertex_count + 1];
    for h in 0..halves {
        start[ends(h).0 as usize + 1] += 1;
    }
    for i in 0..vertex_count {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut bucketed = vec![0u32; halves];
    for h in 0..halves {
        let lo = ends(h).0 as usize;
        bucketed[fill[lo] as usize] = h as u32;
        fill[lo] += 1;
    }
    let mut twins = vec![NONE; halves];
    let mut group: Vec<u32> = Vec::new();
    for v in 0..vertex_count {
        let bucket = &mut bucketed[start[v] as usize..start[v + 1] as usize];
        // Half-edges were filled in increasing order; a stable sort by the larger vertex
        // keeps that order within each edge.
        bucket.sort_by_key(|&h| ends(h as usize).1);
        for same in bucket.chunk_by(|&g, &h| ends(g as usize).1 == ends(h as usize).1) {
            group.clear();
            group.extend_from_slice(same);
            match group.len() {
                1 => {}
                2 => {
                    twins[group[0] as usize] = group[1];
                    twins[group[1] as usize] = group[0];
                }
                count => {
                    let (a, b) = ends(group[0] as usize);
                    return Err(Error::NonManifoldEdge { a, b, count });
                }
            }
        }
    }
    Ok(twins)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_count_is_what_contouring_makes_on_a_generic_grid() {
        // Heights off every level: each crossing is one segment.
        let values: Vec<f64> = (0..49)
            .map(|i| ((i % 7) as f64 * 1.3 + (i / 7) as f64 * 2.1).sin() * 10.0 + 0.05)
            .collect();
        let m = ContourMesh::from_grid(7, 7, &values).unwrap();
        let levels: Vec<f64> = (-10..=10).map(f64::from).collect();
        let lines = crate::contour(&m, &levels).unwrap();
        let made: usize = lines.iter().map(|l| l.points().len() - 1).sum();
        assert_eq!(m.segment_count(&levels), made as u64);
        assert_eq!(m.segment_count(&[]), 0);
    }

    #[test]
    fn grid_mesh_has_two_triangles_per_valid_cell() {
        let nan = f64::NAN;
        let values = [0.0, 1.0, 2.0, 3.0, 4.0, nan, 6.0, 7.0, 8.0];
        let m = ContourMesh::from_grid(3, 3, &values).unwrap();
        // The two right-hand cells touch the nodata sample 5.
        assert_eq!(m.triangles(), &[[0, 1, 4], [0, 4, 3], [3, 4, 7], [3, 7, 6]]);
        assert_eq!(m.height_range(), Some((0.0, 7.0)));
        assert_eq!(m.edge_triangle_count(0, 4), 2);
        assert_eq!(m.edge_triangle_count(4, 3), 2);
        assert_eq!(m.edge_triangle_count(1, 0), 1);
        assert_eq!(m.edge_triangle_count(1, 2), 0);
        // t1's edge 1 (4, 3) is t2's edge 0 (3, 4); t0's edge 1 (1, 4) is on the hole.
        assert_eq!(m.twin(4), 6);
        assert_eq!(m.twin(6), 4);
        assert_eq!(m.twin(1), NONE);
    }

    #[test]
    fn grid_twins_are_the_twins_of_the_triangle_list() {
        // Nodata scattered so that cells are missing beside, above and below others.
        let (w, h) = (9u32, 7u32);
        let values: Vec<f64> = (0..w * h)
            .map(|i| match (i * 7 + 3) % 11 {
                0 => f64::NAN,
                r => f64::from(r),
            })
            .collect();
        let m = ContourMesh::from_grid(w, h, &values).unwrap();
        assert!(m.triangles().len() > 20, "{}", m.triangles().len());
        let general = build_twins(m.vertices().len(), m.triangles()).unwrap();
        assert_eq!(m.twins, general);
        assert!(general.contains(&NONE) && general.iter().any(|&t| t != NONE));
    }

    #[test]
    fn twins_link_shared_edges_only() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let m = ContourMesh::new(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        // t0 edge 2 is (2, 0); t1 edge 0 is (0, 2).
        assert_eq!(m.twin(2), 3);
        assert_eq!(m.twin(3), 2);
        for h in [0, 1, 4, 5] {
            assert_eq!(m.twin(h), NONE);
        }
    }

    #[test]
    fn bad_meshes_are_errors() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, f64::NAN],
            [0.0, 1.0, 0.0],
        ];
        assert!(matches!(
            ContourMesh::new(v.clone(), vec![[0, 1, 9]]),
            Err(Error::VertexOutOfRange { vertex: 9, .. })
        ));
        assert!(matches!(
            ContourMesh::new(v.clone(), vec![[0, 1, 1]]),
            Err(Error::RepeatedVertex { vertex: 1, .. })
        ));
        assert!(matches!(
            ContourMesh::new(v.clone(), vec![[0, 1, 2]]),
            Err(Error::NonFiniteVertex { vertex: 2 })
        ));
        assert!(matches!(
            ContourMesh::new(v, vec![[0, 1, 3], [1, 0, 3], [3, 0, 1]]),
            Err(Error::NonManifoldEdge { count: 3, .. })
        ));
        assert!(matches!(
            ContourMesh::from_grid(2, 2, &[1.0]),
            Err(Error::GridSize { .. })
        ));
    }
}
