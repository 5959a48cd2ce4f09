//! Where finished tiles go: the [`TileSink`] the engine pushes into, in tile order.

use tinsmith_core::{DecimationReport, TinVertex};

use crate::plan::{TileIndex, TileWindow};

/// What a sink may fail with: any error, boxed (the engine adds which tile it was).
pub type SinkError = Box<dyn std::error::Error + Send + Sync>;

/// Receives the finished tiles of [`crate::mesh_tiles`], one at a time, in row-major tile
/// order, on the thread that called `mesh_tiles` (so a sink need not be `Send`).
///
/// The engine calls [`TileSink::tile`] once per tile and nothing else: a sink that writes
/// a file completes it in its own `finish` method, which the caller calls after
/// `mesh_tiles` succeeds. If `mesh_tiles` fails, the caller drops the sink, which must then
/// leave no partial output. [`crate::WeldedWriter`] and [`crate::PerTileWriter`] write mesh
/// files through `tinsmith-formats`.
///
/// Modelled on ripgrep's `grep_searcher::Sink`: the producer pushes, the sink decides what
/// to do with each piece.
pub trait TileSink {
    /// Takes one finished tile, already checked by the verifier. Returning an error stops
    /// the run; `mesh_tiles` returns it with the tile's index.
    fn tile(&mut self, tile: &FinishedTile) -> Result<(), SinkError>;
}

/// One decimated and verified tile, with its vertices numbered in the welded mesh.
///
/// # Welded numbering
/// Vertices of the whole mesh are numbered in tile order: each tile's vertices that no
/// earlier tile has (its *new* vertices) get the next numbers, in the tile's vertex order
/// (row-major); a vertex on an edge shared with an earlier tile keeps the number that
/// tile gave it. So the ids `first_new_id()..first_new_id() + new_vertex_count()` belong to
/// the new vertices, in order, and a triangle only refers to vertices numbered before the
/// end of its tile.
#[derive(Debug, Clone)]
pub struct FinishedTile {
    pub(crate) index: TileIndex,
    pub(crate) window: TileWindow,
    pub(crate) vertices: Vec<TinVertex>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) ids: Vec<u32>,
    pub(crate) first_new_id: u32,
    pub(crate) variables: Vec<Vec<f64>>,
    pub(crate) report: DecimationReport,
    pub(crate) measured_max_error: f64,
}

impl FinishedTile {
    /// The tile's place in the plan.
    pub fn index(&self) -> TileIndex {
        self.index
    }

    /// The tile's samples in the raster.
    pub fn window(&self) -> TileWindow {
        self.window
    }

    /// The tile's vertices in raster coordinates (column, row, value), row-major.
    pub fn vertices(&self) -> &[TinVertex] {
        &self.vertices
    }

    /// Triangles as indices into [`FinishedTile::vertices`], counter-clockwise in raster
    /// coordinates (x = column, y = row).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The welded-mesh id of each vertex of [`FinishedTile::vertices`].
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// The id of the tile's first new vertex: vertices with an id at least this are new.
    pub fn first_new_id(&self) -> u32 {
        self.first_new_id
    }

    /// Whether vertex `i` (of [`FinishedTile::vertices`]) is new in this tile.
    pub fn is_new(&self, i: usize) -> bool {
        self.ids[i] >= self.first_new_id
    }

    /// The tile's new vertices, in welded-id order.
    pub fn new_vertices(&self) -> impl Iterator<Item = &TinVertex> + '_ {
        self.vertices
            .iter()
            .enumerate()
            .filter(|&(i, _)| self.is_new(i))
            .map(|(_, v)| v)
    }

    /// The tile's triangles with welded ids, counter-clockwise in raster coordinates.
    pub fn welded_triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.triangles
            .iter()
            .map(|t| t.map(|local| self.ids[local as usize]))
    }

    /// An error unless this tile's first new vertex is number `written`: a sink that
    /// appends vertices calls it with the count it holds, so tiles out of order are caught.
    pub fn check_follows(&self, written: usize) -> Result<(), SinkError> {
        if written == self.first_new_id as usize {
            return Ok(());
        }
        Err(format!(
            "tiles out of order: {written} vertices so far, the tile's first new one is {}",
            self.first_new_id
        )
        .into())
    }

    /// Each variable's values at [`FinishedTile::vertices`] (one list per variable, in
    /// vertex order); empty without variables.
    pub fn variables(&self) -> &[Vec<f64>] {
        &self.variables
    }

    /// Variable `k`'s values at the tile's new vertices, in welded-id order.
    ///
    /// # Panics
    /// When the run has fewer than `k + 1` variables.
    pub fn new_variable_values(&self, k: usize) -> impl Iterator<Item = f64> + '_ {
        self.variables[k]
            .iter()
            .enumerate()
            .filter(|&(i, _)| self.is_new(i))
            .map(|(_, &x)| x)
    }

    /// The decimation's counts and timings for this tile.
    pub fn report(&self) -> &DecimationReport {
        &self.report
    }

    /// The largest |sample - TIN| the verifier measured over the tile.
    pub fn measured_max_error(&self) -> f64 {
        self.measured_max_error
    }
}
