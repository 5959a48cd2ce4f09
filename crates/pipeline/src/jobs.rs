//! What each run is asked to do, as plain values: the CLI's flags parse into these, and a
//! library caller (bindings, scripts) fills them in directly. Each `new` gives the
//! defaults `tinsmith --help` shows.

use std::path::PathBuf;

use tinsmith_core::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};
use tinsmith_formats::MeshFormat;

use crate::error::bail;
use crate::variables::BandVariable;

/// Samples per tile side (shared row and column included) unless a job says otherwise.
pub const DEFAULT_TILE_SIZE: u32 = tinsmith_tiling::DEFAULT_TILE_SIZE;

/// A mesh run: read band `band` of `input`, decimate it within `max_error` (or to a
/// count), verify the TIN independently and write it to `output` (one file) or
/// `per_tile` (one file per tile). See [`crate::mesh`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MeshJob {
    /// The raster (any GDAL can read).
    pub input: PathBuf,
    /// The mesh file; its format follows the extension unless `export.format` names it.
    pub output: Option<PathBuf>,
    /// The format and its format-specific choices.
    pub export: ExportChoices,
    /// Largest allowed |sample - TIN| at any valid sample; `None` with a count target.
    pub max_error: Option<f64>,
    /// Decimate until at most this many triangles remain (greedy order).
    pub max_triangles: Option<usize>,
    /// Decimate until at most this many vertices remain (greedy order).
    pub max_vertices: Option<usize>,
    /// Band to read, 1-based: the height.
    pub band: usize,
    /// Other bands decimated with the height, each within its own bound (see
    /// [`crate::resolve_bands`]); the domain is where every band is valid. Untiled, exact
    /// error model, PLY or glTF output only.
    pub variables: Vec<BandVariable>,
    /// How a candidate triangle's error is measured.
    pub error_model: ErrorModel,
    /// Edge selection when holes are retriangulated by ears.
    pub selection: EdgeSelection,
    /// Removal order.
    pub order: Order,
    /// Hole retriangulation.
    pub retriangulate: Retriangulation,
    /// Largest hole solved optimally by dynamic programming.
    pub dp_max_ring: u16,
    /// The mesh decimation starts from.
    pub initial_mesh: InitialMesh,
    /// Longest triangle edge allowed, in sample spacings.
    pub max_edge_length: Option<u32>,
    /// Rounds of error-lowering edge flips after decimating.
    pub flip_rounds: usize,
    /// Rounds of extended-hole removals after decimating.
    pub extend_rounds: usize,
    /// Where vertices sit in height.
    pub vertex_heights: VertexHeights,
    /// Shape the TIN for contour lines every this much (plus `contour_offset`).
    pub contour_interval: Option<f64>,
    /// Shift of the `contour_interval` levels.
    pub contour_offset: Option<f64>,
    /// Shape the TIN for contour lines at these levels.
    pub contour_levels: Vec<f64>,
    /// Write (column, row, value) instead of georeferenced coordinates.
    pub pixel_coords: bool,
    /// Where to write the JSON report.
    pub report: Option<PathBuf>,
    /// Samples per tile side; a larger raster is meshed tile by tile.
    pub tile_size: u32,
    /// Worker threads for tiles; `None` or 0 for one per core.
    pub threads: Option<u32>,
    /// Write one mesh file per tile into this directory instead of one welded mesh.
    pub per_tile: Option<PathBuf>,
    /// Format of the `per_tile` files (PLY when `None`).
    pub tile_format: Option<TileFormat>,
    /// A PNG of the mesh's edges over the raster's hillshade (`tinsmith preview`'s
    /// default picture, 1600 pixels), written after the mesh.
    pub preview: Option<PathBuf>,
}

/// The format of the files a per-tile run writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileFormat {
    /// Binary PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
}

/// The output format of a mesh run and its format-specific choices.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct ExportChoices {
    /// The format, whatever the extension; `None` follows the extension.
    pub format: Option<MeshFormat>,
    /// STL only: close the surface into a solid with a floor at this height.
    pub base: Option<f64>,
    /// glTF only: write per-vertex normals.
    pub normals: bool,
    /// GeoJSON only: keep the raster's CRS instead of reprojecting to WGS84.
    pub geojson_source_crs: bool,
}

impl MeshJob {
    /// A run on `input` with every other choice at its default (no output, no bound: set
    /// `output` or `per_tile`, and `max_error` or a count).
    pub fn new(input: impl Into<PathBuf>) -> MeshJob {
        MeshJob {
            input: input.into(),
            output: None,
            export: ExportChoices::default(),
            max_error: None,
            max_triangles: None,
            max_vertices: None,
            band: 1,
            variables: Vec::new(),
            error_model: ErrorModel::default(),
            selection: EdgeSelection::default(),
            order: Order::default(),
            retriangulate: Retriangulation::default(),
            dp_max_ring: 8,
            initial_mesh: InitialMesh::default(),
            max_edge_length: None,
            flip_rounds: 0,
            extend_rounds: 0,
            vertex_heights: VertexHeights::default(),
            contour_interval: None,
            contour_offset: None,
            contour_levels: Vec::new(),
            pixel_coords: false,
            report: None,
            tile_size: DEFAULT_TILE_SIZE,
            threads: None,
            per_tile: None,
            tile_format: None,
            preview: None,
        }
    }

    /// Whether a triangle or vertex count is the target.
    pub fn has_count_target(&self) -> bool {
        self.max_triangles.is_some() || self.max_vertices.is_some()
    }

    /// Whether decimation raises the vertex heights for this job on a raster whose valid
    /// heights span `heights` (the core's rule,
    /// [`DecimationOptions::raises_vertex_heights`], on the options the job gives).
    pub fn raises_vertex_heights(&self, heights: Option<(f64, f64)>) -> bool {
        let max_abs = heights.map_or(0.0, |(lo, hi)| lo.abs().max(hi.abs()));
        let max_error = self.max_error.unwrap_or(f64::INFINITY);
        self.decimation_options(max_error, heights)
            .is_ok_and(|options| options.raises_vertex_heights(max_abs))
    }

    /// The decimation options the job asks for, with `max_error` as the bound (the
    /// untiled path passes the bound less the output format's height rounding); contour
    /// levels from `contour_interval` run over `heights`, the raster's valid range.
    pub fn decimation_options(
        &self,
        max_error: f64,
        heights: Option<(f64, f64)>,
    ) -> crate::Result<DecimationOptions> {
        let mut options = DecimationOptions::new(max_error)
            .with_selection(self.selection)
            .with_error_model(self.error_model)
            .with_order(self.order)
            .with_retriangulation(self.retriangulate)
            .with_initial_mesh(self.initial_mesh);
        options.dp_max_ring = self.dp_max_ring as usize;
        options.max_edge_length = self.max_edge_length;
        options.flip_rounds = self.flip_rounds;
        options.extend_rounds = self.extend_rounds;
        options.vertex_heights = self.vertex_heights;
        if self.has_count_target() && (self.flip_rounds > 0 || self.extend_rounds > 0) {
            bail!(
                "{}: --flip-rounds and --extend-rounds work to an error bound, not with \
                 --max-triangles or --max-vertices",
                self.input.display()
            );
        }
        if let Some(n) = self.max_triangles {
            options = options.with_max_triangles(n);
        }
        if let Some(n) = self.max_vertices {
            options = options.with_max_vertices(n);
        }
        let levels = match (self.contour_interval, heights) {
            (Some(interval), Some((lo, hi))) => {
                let offset = self.contour_offset.unwrap_or(0.0);
                Some(tinsmith_contour::interval_levels(interval, offset, lo, hi)?)
            }
            (Some(_), None) => Some(Vec::new()),
            (None, _) if !self.contour_levels.is_empty() => {
                Some(tinsmith_contour::sorted_levels(&self.contour_levels)?)
            }
            (None, _) => None,
        };
        if let Some(levels) = levels {
            options = options.with_contour_levels(&levels);
        }
        Ok(options)
    }
}

/// A contour run: lines of band `band` of `input`'s TIN (decimated within `max_error`,
/// the full grid at 0, or the `mesh` file) at `levels` or every `interval`, written to
/// `output`. See [`crate::contour`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ContourJob {
    /// The raster (any GDAL can read).
    pub input: PathBuf,
    /// The lines file (.geojson, .json, .fgb).
    pub output: PathBuf,
    /// Contour every multiple of this (plus `offset`) within the height range.
    pub interval: Option<f64>,
    /// Shift of the `interval` levels.
    pub offset: Option<f64>,
    /// Explicit levels (used when `interval` is `None`).
    pub levels: Vec<f64>,
    /// Contour the TIN decimated within this error; `None` or 0 contours the full grid.
    pub max_error: Option<f64>,
    /// Contour this mesh file (written from `input`) instead.
    pub mesh: Option<PathBuf>,
    /// The `mesh` file's format, whatever its extension.
    pub mesh_format: Option<MeshFormat>,
    /// Simplify each line (Douglas-Peucker) within this distance in file units.
    pub simplify: Option<f64>,
    /// Band to read, 1-based.
    pub band: usize,
    /// Write (column, row) coordinates; read `mesh` as written with pixel coordinates.
    pub pixel_coords: bool,
    /// GeoJSON only: keep the raster's CRS instead of reprojecting to WGS84.
    pub geojson_source_crs: bool,
    /// Samples per tile side for a decimated TIN.
    pub tile_size: u32,
    /// Worker threads for tiles; `None` or 0 for one per core.
    pub threads: Option<u32>,
}

impl ContourJob {
    /// Lines of `input` into `output` with every other choice at its default (set
    /// `interval` or `levels`).
    pub fn new(input: impl Into<PathBuf>, output: impl Into<PathBuf>) -> ContourJob {
        ContourJob {
            input: input.into(),
            output: output.into(),
            interval: None,
            offset: None,
            levels: Vec::new(),
            max_error: None,
            mesh: None,
            mesh_format: None,
            simplify: None,
            band: 1,
            pixel_coords: false,
            geojson_source_crs: false,
            tile_size: DEFAULT_TILE_SIZE,
            threads: None,
        }
    }
}

/// A verify run: measure the `mesh` file's true error against band `band` of `input`.
/// See [`crate::verify`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct VerifyJob {
    /// The raster the mesh was made from.
    pub input: PathBuf,
    /// The mesh file.
    pub mesh: PathBuf,
    /// The mesh's format, whatever its extension.
    pub format: Option<MeshFormat>,
    /// The bound the measured error must keep.
    pub max_error: Option<f64>,
    /// Band the mesh was made from, 1-based.
    pub band: usize,
    /// Other bands the mesh carries per vertex, each checked against its bound (the
    /// domain is where every band is valid).
    pub variables: Vec<BandVariable>,
    /// The mesh holds (column, row, value) coordinates.
    pub pixel_coords: bool,
}

impl VerifyJob {
    /// A check of `mesh` against `input` with every other choice at its default.
    pub fn new(input: impl Into<PathBuf>, mesh: impl Into<PathBuf>) -> VerifyJob {
        VerifyJob {
            input: input.into(),
            mesh: mesh.into(),
            format: None,
            max_error: None,
            band: 1,
            variables: Vec::new(),
            pixel_coords: false,
        }
    }
}

/// `tinsmith preview`: a picture of a raster and a TIN of it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PreviewJob {
    /// The raster the mesh was made from.
    pub input: PathBuf,
    /// The mesh file.
    pub mesh: PathBuf,
    /// The PNG to write (`.png`).
    pub output: PathBuf,
    /// The mesh's format, whatever its extension.
    pub format: Option<MeshFormat>,
    /// Band the mesh was made from, 1-based.
    pub band: usize,
    /// The mesh holds (column, row, value) coordinates.
    pub pixel_coords: bool,
    /// The picture's longer side, in pixels.
    pub size: u32,
    /// The raster as a hillshade.
    pub hillshade: bool,
    /// The TIN's edges.
    pub wireframe: bool,
    /// The signed error TIN - raster in colours, with a legend.
    pub error: bool,
    /// The bound the error colours span (default: the measured largest error).
    pub max_error: Option<f64>,
    /// What the PNG's text says the mesh is (default: its path).
    pub mesh_label: Option<String>,
}

impl PreviewJob {
    /// A picture of `mesh` over `input` in `output`: 1600 pixels, hillshade and wireframe.
    pub fn new(
        input: impl Into<PathBuf>,
        mesh: impl Into<PathBuf>,
        output: impl Into<PathBuf>,
    ) -> PreviewJob {
        PreviewJob {
            input: input.into(),
            mesh: mesh.into(),
            output: output.into(),
            format: None,
            band: 1,
            pixel_coords: false,
            size: 1600,
            hillshade: true,
            wireframe: true,
            error: false,
            max_error: None,
            mesh_label: None,
        }
    }
}
