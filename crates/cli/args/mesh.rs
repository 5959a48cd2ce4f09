//! The flags of `tinsmith mesh`, parsed into a [`MeshJob`].

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::{ExportChoices, MeshJob, TileFormat};

use super::numbers::{parse_finite, parse_interval, parse_max_error};
use super::values::{
    ErrorModelArg, InitialMeshArg, OrderArg, RetriangulateArg, SelectionArg, VertexHeightsArg,
};
use super::{PointArgs, VariableArgs};

#[derive(Debug, Args)]
pub struct MeshArgs {
    /// Any single-band raster GDAL can read (GeoTIFF, ESRI ASCII, HGT, VRT, PNG...), or
    /// points: .las, .laz, or .xyz/.csv/.txt text (x y z columns), Delaunay-triangulated
    /// and decimated within --max-error of every point; or an existing TIN (.ply, .obj,
    /// .xml, .fgb) decimated with its own triangles within --max-error of every vertex.
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.ply, .obj, .stl, .glb, .geojson,
    /// .fgb, .xml or .landxml for LandXML) unless --format names it. Optional with --per-tile.
    #[arg(short, long, required_unless_present = "per_tile")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub export: ExportArgs,
    /// Largest allowed |sample - TIN| at any valid sample, in data units. Required unless
    /// --max-triangles or --max-vertices is given. With --bands, one bound for every band
    /// or a comma-separated bound per band.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true,
          value_delimiter = ',', num_args = 1,
          required_unless_present_any = ["max_triangles", "max_vertices"])]
    pub max_error: Vec<f64>,
    /// Decimate until at most N triangles remain (greedy order), then report the verified
    /// max error.
    #[arg(long, value_name = "N")]
    pub max_triangles: Option<usize>,
    /// Decimate until at most N vertices remain (greedy order).
    #[arg(long, value_name = "N")]
    pub max_vertices: Option<usize>,
    /// Band to read (1-based).
    #[arg(long, default_value_t = 1, conflicts_with = "bands")]
    pub band: usize,
    /// Mesh heights above the WGS84 ellipsoid, turned from heights above this geoid
    /// (egm96, egm2008 or a geoid grid file) at every sample through PROJ; the bound holds
    /// against the converted heights, and the file's CRS loses INPUT's vertical part.
    /// Default: the band's heights as they are.
    #[arg(long, value_name = "DATUM", value_parser = parse_datum)]
    pub vertical_datum: Option<tinsmith_raster::VerticalDatum>,
    /// Several variables over one mesh: these bands (comma-separated, 1-based), each
    /// within its own --max-error at every sample; a vertex goes only when every band
    /// stays within its bound. The first (or --height-band) is the height, the others are
    /// written per vertex (PLY: a property named after the band's description or band_N;
    /// glTF: a _NAME attribute; three 8-bit bands also as vertex colours, OBJ included),
    /// or per triangle (GeoJSON, FlatGeobuf: corner means). The domain is where every
    /// band is valid. Exact error model; tiled runs write PLY, GeoJSON or FlatGeobuf.
    #[arg(long, value_delimiter = ',', num_args = 1, value_name = "B,B,...")]
    pub bands: Vec<usize>,
    #[command(flatten)]
    pub variables: VariableArgs,
    /// Error model.
    #[arg(long, value_enum, default_value_t = ErrorModelArg::Exact)]
    pub error_model: ErrorModelArg,
    /// Edge selection rule for retriangulating holes by ears (paper §3.4).
    #[arg(long, value_enum, default_value_t = SelectionArg::Hybrid)]
    pub selection: SelectionArg,
    /// Removal order.
    #[arg(long, value_enum, default_value_t = OrderArg::Sweep)]
    pub order: OrderArg,
    /// Hole retriangulation.
    #[arg(long, value_enum, default_value_t = RetriangulateArg::Dp)]
    pub retriangulate: RetriangulateArg,
    /// Largest hole (ring vertices) that --retriangulate dp solves optimally; larger ones
    /// use ears. DP costs O(n^3) triangle evaluations.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u16).range(3..=64))]
    pub dp_max_ring: u16,
    /// The mesh decimation starts from.
    #[arg(long, value_enum, default_value_t = InitialMeshArg::Auto)]
    pub initial_mesh: InitialMeshArg,
    /// Longest triangle edge allowed, in sample spacings (at least 2): no long slivers,
    /// at the cost of more triangles. The error bound holds either way.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..))]
    pub max_edge_length: Option<u32>,
    /// After decimating, up to N rounds of edge flips that lower triangle errors, each
    /// followed by another sweep: fewer triangles at small bounds, at more time; the
    /// error bound holds either way. Not with --max-triangles/--max-vertices.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub flip_rounds: usize,
    /// After decimating, up to N rounds that try each vertex left again with its hole
    /// extended across its ring edges, each followed by another sweep: 3-7 % fewer
    /// triangles, for 3-6 x the time; the error bound holds either way.
    /// Not with --max-triangles/--max-vertices.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub extend_rounds: usize,
    /// Where vertices sit in height. The error bound holds at every sample either way.
    #[arg(long, value_enum, default_value_t = VertexHeightsArg::Raised)]
    pub vertex_heights: VertexHeightsArg,
    /// Shape the TIN for contour lines every I (plus --contour-offset) over the raster's
    /// heights, as `tinsmith contour --max-error` does: `contour --mesh` then draws lines
    /// with fewer segments. The error bound holds either way.
    #[arg(long, value_name = "I", value_parser = parse_interval, allow_hyphen_values = true, conflicts_with = "contour_levels")]
    pub contour_interval: Option<f64>,
    /// Shift of the --contour-interval levels: offset + k * interval.
    #[arg(long, value_name = "O", requires = "contour_interval", value_parser = parse_finite, allow_hyphen_values = true)]
    pub contour_offset: Option<f64>,
    /// Shape the TIN for contour lines at these levels, comma-separated (see
    /// --contour-interval).
    #[arg(long, value_delimiter = ',', value_parser = parse_finite, allow_hyphen_values = true)]
    pub contour_levels: Vec<f64>,
    /// Write (column, row, value) instead of georeferenced coordinates.
    #[arg(long)]
    pub pixel_coords: bool,
    /// No progress or summary on stderr (progress is shown only on a terminal anyway).
    #[arg(short, long)]
    pub quiet: bool,
    /// Write a JSON report of sizes, counts, measured error and timings.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
    /// Also write a PNG of the mesh's edges over the raster's hillshade, as `tinsmith
    /// preview` draws it (1600 pixels); untiled meshes only.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// Samples per tile side, shared row and column included: a raster wider or taller
    /// than this is meshed tile by tile (in parallel, in bounded memory).
    #[arg(long, value_name = "N", default_value_t = tinsmith_pipeline::DEFAULT_TILE_SIZE,
          value_parser = clap::value_parser!(u32).range(2..))]
    pub tile_size: u32,
    /// Worker threads for tiles, at most 1024; 0 (the default) for one per core, as in
    /// `tiles`. No more are started than there are cores or tiles: more would only wait,
    /// each with its tiles in memory.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=1024))]
    pub threads: Option<u32>,
    /// Write one mesh file per tile into DIR (which must not exist, or be empty) instead
    /// of one welded mesh; always uses tiles.
    #[arg(long, value_name = "DIR", conflicts_with = "output")]
    pub per_tile: Option<PathBuf>,
    /// Format of the --per-tile files [default: ply]. Only with --per-tile.
    // Checked in `mesh::run`: clap's `requires` lets it through beside -o.
    #[arg(long, value_enum)]
    pub tile_format: Option<TileFormatArg>,
    #[command(flatten)]
    pub points: PointArgs,
    /// Points only: the CRS to write (EPSG:CODE, WKT, ...), instead of the file's.
    #[arg(long, value_name = "CRS", help_heading = "Point input")]
    pub crs: Option<String>,
    /// A concave hull instead of the convex one: outer triangles are removed, repeatedly,
    /// while an outer edge (not a breakline or boundary edge) is longer than L (in the
    /// points' x, y units); points left outside are dropped (counted in the report). A
    /// raster's valid samples are then its points.
    #[arg(long, value_name = "L", help_heading = "Point input", value_parser = positive_length)]
    pub hull_edge_length: Option<f64>,
}

fn positive_length(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a positive length")),
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum TileFormatArg {
    /// Binary PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
}

/// Output format and format-specific options of `mesh`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Output format, whatever the extension: ply, obj, stl, glb, geojson, fgb, landxml.
    #[arg(long, value_name = "NAME", value_parser = tinsmith_pipeline::parse_format)]
    pub format: Option<MeshFormat>,
    /// STL only: close the surface into a watertight solid, with walls along every
    /// boundary down to z = Z and a bottom at Z (Z below every height).
    #[arg(long, value_name = "Z", allow_hyphen_values = true)]
    pub base: Option<f64>,
    /// glTF only: write per-vertex normals.
    #[arg(long)]
    pub normals: bool,
    /// GeoJSON only: keep the raster's CRS (with a "crs" member and a note) instead of
    /// reprojecting to WGS84 longitude/latitude as RFC 7946 wants.
    #[arg(long)]
    pub geojson_source_crs: bool,
}

impl MeshArgs {
    /// The job these flags ask for; fails when --bands, --max-error and --height-band
    /// do not fit together.
    pub fn job(&self) -> tinsmith_pipeline::Result<MeshJob> {
        let mut job = MeshJob::new(&self.input);
        job.output = self.output.clone();
        job.export = self.export.choices();
        let (band, max_error, variables) =
            self.variables
                .resolve(&self.input, self.band, &self.bands, &self.max_error)?;
        job.band = band;
        job.vertical_datum = self.vertical_datum.clone();
        job.variables = variables;
        let choices = &mut job.decimation;
        choices.max_error = max_error;
        choices.max_triangles = self.max_triangles;
        choices.max_vertices = self.max_vertices;
        choices.error_model = self.error_model.into();
        choices.selection = self.selection.into();
        choices.order = self.order.into();
        choices.retriangulate = self.retriangulate.into();
        choices.dp_max_ring = self.dp_max_ring;
        choices.initial_mesh = self.initial_mesh.into();
        choices.max_edge_length = self.max_edge_length;
        choices.flip_rounds = self.flip_rounds;
        choices.extend_rounds = self.extend_rounds;
        choices.vertex_heights = self.vertex_heights.into();
        choices.contour_interval = self.contour_interval;
        choices.contour_offset = self.contour_offset;
        choices.contour_levels = self.contour_levels.clone();
        job.pixel_coords = self.pixel_coords;
        job.report = self.report.clone();
        job.preview = self.preview.clone();
        job.tile_size = self.tile_size;
        job.threads = self.threads;
        job.per_tile = self.per_tile.clone();
        job.tile_format = self.tile_format.map(|f| match f {
            TileFormatArg::Ply => TileFormat::Ply,
            TileFormatArg::Obj => TileFormat::Obj,
        });
        job.points = self.points.choices(self.crs.clone());
        job.points.hull_edge_length = self.hull_edge_length;
        Ok(job)
    }
}

impl ExportArgs {
    fn choices(&self) -> ExportChoices {
        let mut choices = ExportChoices::default();
        choices.format = self.format;
        choices.base = self.base;
        choices.normals = self.normals;
        choices.geojson_source_crs = self.geojson_source_crs;
        choices
    }
}

/// A `--vertical-datum` value: `egm96`, `egm2008`, `ellipsoid` or a geoid grid file.
pub fn parse_datum(text: &str) -> Result<tinsmith_raster::VerticalDatum, String> {
    match text.trim() {
        "" => Err("give egm96, egm2008, ellipsoid or a geoid grid file".into()),
        text => Ok(tinsmith_raster::VerticalDatum::parse(text)),
    }
}
