//! The flags of `tinsmith mesh`, parsed into a [`MeshJob`].

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::{Duplicates, ExportChoices, MeshJob, PointChoices, TileFormat};

use super::values::{
    ErrorModelArg, InitialMeshArg, OrderArg, RetriangulateArg, SelectionArg, VertexHeightsArg,
};
use super::{parse_finite, parse_interval, parse_max_error};

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

/// The flags of point input (LAS/LAZ, XYZ/CSV text), shared by `mesh` and `verify`.
#[derive(Debug, Args)]
pub struct PointArgs {
    /// LAS classes to keep, comma-separated [default: 2 (ground) when the file has any
    /// ground point, else every class].
    #[arg(
        long,
        value_name = "C,..",
        value_delimiter = ',',
        help_heading = "Point input"
    )]
    pub classes: Vec<u8>,
    /// Drop LAS points flagged withheld.
    #[arg(long, help_heading = "Point input")]
    pub no_withheld: bool,
    /// Which height a position with several points keeps (see docs/cli.md, "Point
    /// input", for how the default was chosen).
    #[arg(long, value_enum, default_value_t = DuplicatesArg::Lowest, help_heading = "Point input")]
    pub duplicates: DuplicatesArg,
    /// Keep the segments of this OGR line or polygon layer (GeoPackage, Shapefile,
    /// GeoJSON, FlatGeobuf...) as TIN edges, in the input's CRS. Lines with Z keep their
    /// heights, 2D lines take the points'; vertices go on the points' lattice; crossing
    /// lines are split where they cross. A raster's valid samples are then its points.
    /// With verify: check every segment is a chain of mesh edges.
    #[arg(long, value_name = "FILE", help_heading = "Point input")]
    pub breaklines: Option<PathBuf>,
    /// The TIN's outline and holes, an OGR polygon layer in the input's CRS, kept as
    /// edges; points (or a raster's samples) outside are dropped (counted in the report),
    /// and `verify` measures only the points inside.
    #[arg(long, value_name = "FILE", help_heading = "Point input")]
    pub boundary: Option<PathBuf>,
    /// OGR point layers (GeoPackage, Shapefile, FlatGeobuf) only: the attribute holding
    /// the heights [default: the points' Z].
    #[arg(long, value_name = "NAME", help_heading = "Point input")]
    pub z_field: Option<String>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum DuplicatesArg {
    /// The lowest height.
    Lowest,
    /// The highest height.
    Highest,
    /// The mean of the heights.
    Mean,
    /// The first in file order.
    First,
}

impl PointArgs {
    /// The point choices these flags ask for (`crs` from `mesh --crs`).
    pub fn choices(&self, crs: Option<String>) -> PointChoices {
        let mut choices = PointChoices::default();
        choices.classes = (!self.classes.is_empty()).then(|| self.classes.clone());
        choices.no_withheld = self.no_withheld;
        choices.duplicates = match self.duplicates {
            DuplicatesArg::Lowest => Duplicates::Lowest,
            DuplicatesArg::Highest => Duplicates::Highest,
            DuplicatesArg::Mean => Duplicates::Mean,
            DuplicatesArg::First => Duplicates::First,
        };
        choices.crs = crs;
        choices.breaklines = self.breaklines.clone();
        choices.boundary = self.boundary.clone();
        choices.z_field = self.z_field.clone();
        choices
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

/// `--height-band`, `--attributes` and `--attribute-error`: what `mesh` and `verify` take
/// besides `--bands` to make or check several variables over one mesh.
#[derive(Debug, Args)]
pub struct VariableArgs {
    /// With --bands: the band that is the height (listed in --bands) [default: the first].
    #[arg(long, value_name = "N", requires = "bands")]
    pub height_band: Option<usize>,
    /// Variables from another raster: FILE's bands B,... (all without :B,...), each within
    /// --attribute-error, as --bands' are. On another grid than the input's (size,
    /// geotransform or CRS) it is resampled onto it by GDAL (--attribute-resampling);
    /// refused, naming it, when it does not overlap the input.
    #[arg(long, value_name = "FILE[:B,B,...]", requires = "attribute_error")]
    pub attributes: Option<String>,
    /// How --attributes is resampled onto the input's grid when it is on another one
    /// (GDAL's warper; the report says when it was).
    #[arg(long, value_name = "METHOD", default_value = "bilinear", requires = "attributes",
          value_parser = parse_resampling)]
    pub attribute_resampling: tinsmith_raster::Resampling,
    /// The bound of each --attributes band: one for all, or a comma-separated one per band.
    #[arg(long, value_name = "E", value_parser = parse_max_error, allow_hyphen_values = true,
          value_delimiter = ',', num_args = 1, requires = "attributes")]
    pub attribute_error: Vec<f64>,
}

impl VariableArgs {
    /// The height's band (`band` without `bands`), its bound and the variables that
    /// `bands`, `max_error` (one bound, or one per band) and these flags ask for.
    pub fn resolve(
        &self,
        input: &std::path::Path,
        band: usize,
        bands: &[usize],
        max_error: &[f64],
    ) -> tinsmith_pipeline::Result<(usize, Option<f64>, Vec<tinsmith_pipeline::BandVariable>)> {
        let (height, max_error, mut variables) =
            tinsmith_pipeline::resolve_bands(input, bands, max_error, self.height_band)?;
        if let Some(spec) = &self.attributes {
            variables.extend(tinsmith_pipeline::attribute_variables(
                spec,
                &self.attribute_error,
                self.attribute_resampling,
            )?);
        }
        let band = if bands.is_empty() { band } else { height };
        Ok((band, max_error, variables))
    }
}

/// `--attribute-resampling`: one of GDAL's methods tinsmith offers.
fn parse_resampling(text: &str) -> Result<tinsmith_raster::Resampling, String> {
    tinsmith_raster::Resampling::ALL
        .into_iter()
        .find(|m| m.name() == text)
        .ok_or_else(|| {
            let names: Vec<&str> = tinsmith_raster::Resampling::ALL
                .iter()
                .map(|m| m.name())
                .collect();
            format!("expected one of {}", names.join(", "))
        })
}
