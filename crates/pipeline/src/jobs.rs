//! What each run is asked to do, as plain values: the CLI's flags parse into these, and a
//! library caller (bindings, scripts) fills them in directly. Each `new` gives the
//! defaults `tinsmith --help` shows.

use std::path::PathBuf;

use tinsmith_choices::DecimationChoices;
use tinsmith_core::DecimationOptions;
use tinsmith_formats::MeshFormat;
use tinsmith_raster::VerticalDatum;

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
    /// The decimation asked for: bound or count, orders, holes, contour levels.
    pub decimation: DecimationChoices,
    /// Band to read, 1-based.
    pub band: usize,
    /// The geoid the band's heights are above, to mesh them as heights above the WGS84
    /// ellipsoid (see `tinsmith_raster::read_samples_on`); `None` meshes them as they
    /// are.
    pub vertical_datum: Option<VerticalDatum>,
    /// Other bands decimated with the height, each within its own bound (see
    /// [`crate::resolve_bands`]); the domain is where every band is valid. Exact error
    /// model, formats that carry per-vertex values (tiled: PLY, GeoJSON, FlatGeobuf; no
    /// `--per-tile`).
    pub variables: Vec<BandVariable>,
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
    /// Point input (LAS/LAZ, XYZ/CSV text): which points and how duplicates merge.
    pub points: PointChoices,
}

/// The choices that apply to point input only.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct PointChoices {
    /// LAS classes to keep; `None`: ground (class 2) if the file has any, else all.
    pub classes: Option<Vec<u8>>,
    /// Drop LAS points flagged withheld.
    pub no_withheld: bool,
    /// Which height a position with several points keeps.
    pub duplicates: tinsmith_points::Duplicates,
    /// The CRS to write (anything GDAL's `SetFromUserInput` takes), instead of the file's.
    pub crs: Option<String>,
    /// A line or polygon layer whose segments the TIN keeps as edges (constrained
    /// Delaunay triangulation; their vertices are never removed).
    pub breaklines: Option<std::path::PathBuf>,
    /// A polygon layer: the TIN's outline and holes (constrained edges); points outside
    /// are dropped.
    pub boundary: Option<std::path::PathBuf>,
    /// Remove outer triangles while an outer edge is longer than this (a concave hull).
    pub hull_edge_length: Option<f64>,
    /// OGR point layers: the attribute holding heights, instead of the geometries' Z.
    pub z_field: Option<String>,
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
            decimation: DecimationChoices::default(),
            band: 1,
            vertical_datum: None,
            variables: Vec::new(),
            pixel_coords: false,
            report: None,
            tile_size: DEFAULT_TILE_SIZE,
            threads: None,
            per_tile: None,
            tile_format: None,
            preview: None,
            points: PointChoices::default(),
        }
    }

    /// The decimation options the job asks for, with `bound` as the bound (the untiled
    /// path passes the asked bound less the output format's height rounding); contour
    /// levels from an interval run over `heights`, the raster's valid range.
    pub fn decimation_options(
        &self,
        bound: f64,
        heights: Option<(f64, f64)>,
    ) -> crate::Result<DecimationOptions> {
        use tinsmith_choices::ChoiceError;
        self.decimation
            .decimation_options(bound, heights)
            .map_err(|e| {
                // The choices' refusals in the CLI's own words.
                let reason = match e {
                    ChoiceError::NoTarget => {
                        "give --max-error, or --max-triangles or --max-vertices".to_owned()
                    }
                    ChoiceError::RoundsWithCount => "--flip-rounds and --extend-rounds work to \
                         an error bound, not with --max-triangles or --max-vertices"
                        .to_owned(),
                    other => other.to_string(),
                };
                crate::error::Error::Refused(format!("{}: {reason}", self.input.display()))
            })
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
    /// The mesh was made with heights converted from this geoid (`MeshJob::vertical_datum`):
    /// the band is read the same way.
    pub vertical_datum: Option<VerticalDatum>,
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
            vertical_datum: None,
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
    /// The mesh was made with heights converted from this geoid: the band is read the
    /// same way.
    pub vertical_datum: Option<VerticalDatum>,
    /// The variables the mesh was made with (`mesh --bands` or `--attributes`): its
    /// domain is where every one of them is valid too, and the picture checks it there.
    pub variables: Vec<BandVariable>,
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
            vertical_datum: None,
            variables: Vec::new(),
        }
    }
}
