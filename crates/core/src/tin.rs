//! The decimated mesh handed to callers: kept samples and triangles.

/// A vertex of the output TIN: a kept grid sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TinVertex {
    /// Column of the sample.
    pub x: u32,
    /// Row of the sample.
    pub y: u32,
    /// The sample's value, unchanged.
    pub z: f64,
}

/// A triangulated irregular network over a grid's domain.
///
/// Every vertex is a valid grid sample with its original value; every triangle is
/// non-degenerate and counter-clockwise in grid coordinates (x = column, y = row, so
/// `(b - a) x (c - a) > 0`); the triangles tile the grid's domain exactly.
/// Vertices are ordered by row, then column; triangles by their position in the mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tin {
    pub(crate) vertices: Vec<TinVertex>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

impl Tin {
    /// The kept samples.
    pub fn vertices(&self) -> &[TinVertex] {
        &self.vertices
    }

    /// Triangles as indices into [`Tin::vertices`], counter-clockwise in grid coordinates.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}
