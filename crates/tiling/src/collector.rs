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
    variables: Vec<Vec<f64>>,
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

    /// Takes each variable's values at the welded mesh's vertices, in vertex order (one
    /// list per variable; empty without variables), leaving none.
    pub fn take_variables(&mut self) -> Vec<Vec<f64>> {
        std::mem::take(&mut self.variables)
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
        if self.variables.len() < tile.variables().len() {
            self.variables.resize(tile.variables().len(), Vec::new());
        }
        for (k, values) in self.variables.iter_mut().enumerate() {
            values.extend(tile.new_variable_values(k));
        }
        Ok(())
    }
}
