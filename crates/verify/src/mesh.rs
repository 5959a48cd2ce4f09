//! The mesh being checked: borrowed vertex positions, heights and triangles.

/// A borrowed triangle mesh whose vertices sit on grid samples.
///
/// `positions[i]` is vertex `i`'s integer grid position `[column, row]` and `heights[i]` its
/// z as stored in the mesh (not looked up in the grid, so a wrong height shows up as error).
/// Each triangle holds three indices into `positions`. The lengths are checked by
/// [`verify`](crate::verify), not here.
#[derive(Debug, Clone, Copy)]
pub struct MeshRef<'a> {
    /// Integer grid position `[column, row]` of each vertex.
    pub positions: &'a [[i64; 2]],
    /// Height of each vertex, one per position.
    pub heights: &'a [f64],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
}

impl<'a> MeshRef<'a> {
    /// A mesh over `positions` (with one height each) and `triangles`.
    pub fn new(positions: &'a [[i64; 2]], heights: &'a [f64], triangles: &'a [[u32; 3]]) -> Self {
        Self {
            positions,
            heights,
            triangles,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_keeps_the_slices() {
        let positions = [[0, 0], [1, 0], [0, 1]];
        let heights = [1.0, 2.0, 3.0];
        let triangles = [[0, 1, 2]];
        let mesh = MeshRef::new(&positions, &heights, &triangles);
        assert_eq!(mesh.positions, &positions);
        assert_eq!(mesh.heights, &heights);
        assert_eq!(mesh.triangles, &triangles);
    }
}
