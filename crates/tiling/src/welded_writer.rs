//! The sink that writes one welded mesh file: shared edge vertices once, global indices.

use std::path::Path;

use tinsmith_formats::{MeshFormat, MeshStreamWriter};

use crate::error::Result;
use crate::sink::{FinishedTile, SinkError, TileSink};
use tinsmith_georef::Placement;

/// Writes the tiles of a run as one mesh file (PLY or OBJ), streamed: each tile's new
/// vertices and its triangles are appended as the tile arrives, so memory does not grow
/// with the mesh.
///
/// Vertices are numbered as [`FinishedTile`] describes (tile order; a shared edge vertex
/// once, by the first tile that has it). The file appears, complete, when
/// [`WeldedWriter::finish`] succeeds; until then it is spooled in temporary files in the
/// output directory, removed if the writer is dropped (see
/// `tinsmith_formats::MeshStreamWriter`).
#[derive(Debug)]
pub struct WeldedWriter {
    stream: MeshStreamWriter,
    placement: Placement,
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Each variable's values at the tile's new vertices (with variable names).
    variables: Vec<Vec<f64>>,
}

impl WeldedWriter {
    /// Starts the mesh file `path` in `format`, with the CRS (if any) in its header and
    /// coordinates mapped by `placement`.
    ///
    /// # Errors
    /// [`crate::Error::Write`] when the output directory is missing or not writable.
    pub fn create(
        path: &Path,
        format: MeshFormat,
        crs_wkt: Option<&str>,
        placement: Placement,
    ) -> Result<WeldedWriter> {
        Ok(WeldedWriter {
            stream: MeshStreamWriter::create(path, format, crs_wkt)?,
            placement,
            vertices: Vec::new(),
            triangles: Vec::new(),
            variables: Vec::new(),
        })
    }

    /// Writes the run's variables too, one `double` vertex property each under these
    /// names, in the variables' order (PLY only; the values of
    /// [`FinishedTile::new_variable_values`]).
    ///
    /// # Errors
    /// [`crate::Error::Write`] for OBJ, which carries no per-vertex values.
    pub fn with_variable_names(mut self, names: Vec<String>) -> Result<WeldedWriter> {
        self.variables = vec![Vec::new(); names.len()];
        self.stream = self.stream.with_attribute_names(names)?;
        Ok(self)
    }

    /// Vertices written so far.
    pub fn vertex_count(&self) -> usize {
        self.stream.vertex_count()
    }

    /// Triangles written so far.
    pub fn triangle_count(&self) -> usize {
        self.stream.triangle_count()
    }

    /// Completes the file and moves it into place.
    ///
    /// # Errors
    /// [`crate::Error::Write`]; the target is then untouched.
    pub fn finish(self) -> Result<()> {
        Ok(self.stream.finish()?)
    }
}

impl TileSink for WeldedWriter {
    fn tile(&mut self, tile: &FinishedTile) -> std::result::Result<(), SinkError> {
        tile.check_follows(self.stream.vertex_count())?;
        self.vertices.clear();
        self.vertices.extend(tile.new_vertices().map(|v| {
            let [x, y] = self.placement.file_position(v.x, v.y);
            [x, y, v.z]
        }));
        if self.variables.is_empty() {
            self.stream.write_vertices(&self.vertices)?;
        } else {
            if tile.variables().len() < self.variables.len() {
                return Err(format!(
                    "the tile has {} variables, {} were named",
                    tile.variables().len(),
                    self.variables.len()
                )
                .into());
            }
            for (k, values) in self.variables.iter_mut().enumerate() {
                values.clear();
                values.extend(tile.new_variable_values(k));
            }
            let lists: Vec<&[f64]> = self.variables.iter().map(Vec::as_slice).collect();
            self.stream
                .write_vertices_with_attributes(&self.vertices, &lists)?;
        }
        self.triangles.clear();
        self.triangles
            .extend(tile.welded_triangles().map(|t| self.placement.orient(t)));
        self.stream.write_triangles(&self.triangles)?;
        Ok(())
    }
}
