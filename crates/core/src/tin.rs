//! The decimated mesh handed to callers: kept samples and triangles.

/// A vertex of the output TIN: at a kept grid sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TinVertex {
    /// Column of the sample.
    pub x: u32,
    /// Row of the sample.
    pub y: u32,
    /// The vertex's height: the sample's value, or that raised by less than
    /// `max_error / RAISED_HEIGHT_SHARE` (see [`crate::VertexHeights`]).
    pub z: f64,
}

/// A triangulated irregular network over a grid's domain.
///
/// Every vertex is at a valid grid sample, with its value or raised above it (see
/// [`crate::VertexHeights`]); every triangle is
/// non-degenerate and counter-clockwise in grid coordinates (x = column, y = row, so
/// `(b - a) x (c - a) > 0`); the triangles tile the grid's domain exactly.
/// Vertices are ordered by row, then column; triangles by their position in the mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tin {
    pub(crate) vertices: Vec<TinVertex>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

impl Tin {
    /// The vertices, at the kept samples.
    pub fn vertices(&self) -> &[TinVertex] {
        &self.vertices
    }

    /// Triangles as indices into [`Tin::vertices`], counter-clockwise in grid coordinates.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}
