//! The sink that writes one mesh file per tile into a directory.

use std::path::{Path, PathBuf};

use tinsmith_formats::{write_mesh, MeshFormat, MeshRef, VertexAttribute};
use tinsmith_output::StagedDir;

use crate::error::{Error, Result};
use crate::plan::TileIndex;
use crate::sink::{FinishedTile, SinkError, TileSink};
use tinsmith_georef::Placement;

/// Writes each tile as its own mesh file, [`PerTileWriter::file_name`], into a directory.
///
/// Each file holds all of its tile's vertices (shared edge vertices appear in every tile
/// that has them, at identical coordinates, and with the same values of every variable)
/// with indices local to the file; tiles without
/// any triangle (all nodata) are written as empty meshes, so there is one file per tile.
///
/// The directory appears, complete, when [`PerTileWriter::finish`] succeeds: files go to a
/// temporary directory beside it, renamed into place at the end; dropping the writer
/// removes it. The directory must not exist yet, or be empty.
#[derive(Debug)]
pub struct PerTileWriter {
    dir: PathBuf,
    /// The temporary directory the files go to, registered for removal on a signal.
    temp: StagedDir,
    format: MeshFormat,
    crs_wkt: Option<String>,
    placement: Placement,
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// The names the files give the run's variables, in order.
    variable_names: Vec<String>,
}

impl PerTileWriter {
    /// Prepares to write tiles into `dir` in `format`, with the CRS (if any) in each file
    /// and coordinates mapped by `placement`.
    ///
    /// # Errors
    /// [`Error::Output`] when `dir` exists and is not an empty directory, its parent does
    /// not exist, or the temporary directory cannot be created.
    pub fn create(
        dir: &Path,
        format: MeshFormat,
        crs_wkt: Option<&str>,
        placement: Placement,
    ) -> Result<PerTileWriter> {
        let output = |reason: &str, source| Error::Output {
            path: dir.to_path_buf(),
            reason: reason.to_owned(),
            source,
        };
        let temp = StagedDir::new(dir, false).map_err(|error| match error {
            tinsmith_output::Error::Occupied { reason, .. } => output(reason, None),
            tinsmith_output::Error::FileInTheWay { file, .. } => output(
                &format!(
                    "{} is a file, so no directory can be made there",
                    file.display()
                ),
                None,
            ),
            tinsmith_output::Error::MissingDirectory { dir: parent, .. } => output(
                &format!("parent directory {} does not exist", parent.display()),
                None,
            ),
            tinsmith_output::Error::Io { source, .. } => output(
                "cannot create a temporary directory beside it",
                Some(source),
            ),
            other => output(&other.to_string(), None),
        })?;
        Ok(PerTileWriter {
            dir: dir.to_path_buf(),
            temp,
            format,
            crs_wkt: crs_wkt.map(str::to_owned),
            placement,
            vertices: Vec::new(),
            triangles: Vec::new(),
            variable_names: Vec::new(),
        })
    }

    /// Writes the run's variables too, one per-vertex attribute each, under these names
    /// (in the variables' order; the format must carry attributes, as PLY does). A tile
    /// with fewer variables than names is an error of the sink.
    pub fn with_variable_names(mut self, names: Vec<String>) -> PerTileWriter {
        self.variable_names = names;
        self
    }

    /// The file name of tile `index`: `tile_r{row}_c{col}.{extension}`.
    pub fn file_name(index: TileIndex, format: MeshFormat) -> String {
        format!("tile_r{}_c{}.{}", index.row, index.col, format.extension())
    }

    /// Moves the finished directory into place.
    ///
    /// # Errors
    /// [`Error::Output`] when the rename fails (for example because the directory was
    /// created meanwhile and is not empty); the temporary directory is then removed.
    pub fn finish(self) -> Result<()> {
        self.temp.commit().map_err(|e| Error::Output {
            path: self.dir.clone(),
            reason: "cannot move the finished tiles into place".to_owned(),
            source: Some(e),
        })
    }
}

impl TileSink for PerTileWriter {
    fn tile(&mut self, tile: &FinishedTile) -> std::result::Result<(), SinkError> {
        self.vertices.clear();
        self.vertices.extend(tile.vertices().iter().map(|v| {
            let [x, y] = self.placement.file_position(v.x, v.y);
            [x, y, v.z]
        }));
        self.triangles.clear();
        self.triangles
            .extend(tile.triangles().iter().map(|&t| self.placement.orient(t)));
        let path = self
            .temp
            .path()
            .join(PerTileWriter::file_name(tile.index(), self.format));
        if tinsmith_output::interrupted() {
            // The temporary directory is being removed: add nothing to it.
            return Err(std::io::Error::from(std::io::ErrorKind::Interrupted).into());
        }
        if tile.variables().len() < self.variable_names.len() {
            return Err(format!(
                "the tile has {} variables, {} were named",
                tile.variables().len(),
                self.variable_names.len()
            )
            .into());
        }
        let attributes: Vec<VertexAttribute<'_>> = (self.variable_names.iter())
            .zip(tile.variables())
            .map(|(name, values)| VertexAttribute { name, values })
            .collect();
        let mesh = MeshRef::new(&self.vertices, &self.triangles)
            .with_crs_wkt(self.crs_wkt.as_deref())
            .with_attributes(&attributes);
        write_mesh(&path, self.format, mesh)?;
        Ok(())
    }
}
