//! The sink that keeps the welded mesh in memory, for callers that need it whole (the
//! mesh formats that cannot be streamed).

use crate::sink::{FinishedTile, SinkError, TileSink};

/// Collects the tiles of a run into one welded mesh in memory: vertices in raster
/// coordinates (column, row, value), numbered as [`FinishedTile`] describes, and triangles
/// counter-clockwise in raster coordinates. Memory is the welded mesh, not the raster.
#[derive(Debug, Default)]
pub struct MeshCollector {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl MeshCollector {
    /// An empty collector.
    pub fn new() -> MeshCollector {
        MeshCollector::default()
    }

    /// The welded mesh: vertices (column, row, value) and triangles indexing them.
    pub fn into_parts(self) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (self.vertices, self.triangles)
    }
}

impl TileSink for MeshCollector {
    fn tile(&mut self, tile: &FinishedTile) -> Result<(), SinkError> {
        tile.check_follows(self.vertices.len())?;
        self.vertices.extend(
            tile.new_vertices()
                .map(|v| [f64::from(v.x), f64::from(v.y), v.z]),
        );
        self.triangles.extend(tile.welded_triangles());
        Ok(())
    }
}
