//! Command-line flags (clap), parsed into plain values the commands use.

use std::path::PathBuf;

use clap::{ArgGroup, Args, Parser, Subcommand, ValueEnum};
use tinsmith_core::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};
use tinsmith_export::MeshFormat;

/// Turns DEMs and other 2D scalar grids into TINs whose error is guaranteed.
#[derive(Debug, Parser)]
#[command(name = "tinsmith", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Every command reads negative numbers as values, so `--max-triangles -5` is refused as
/// an invalid count rather than as an unknown flag.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print a raster's size, type, nodata, CRS, geotransform and value range.
    #[command(allow_negative_numbers = true)]
    Info(InfoArgs),
    /// Decimate a raster into a TIN within --max-error of every valid sample.
    #[command(allow_negative_numbers = true)]
    Mesh(MeshArgs),
    /// Measure a TIN's true error against its raster at every valid sample.
    #[command(allow_negative_numbers = true)]
    Verify(VerifyArgs),
    /// Contour lines of the raster's TIN (decimated within --max-error, or given).
    #[command(allow_negative_numbers = true)]
    Contour(ContourArgs),
    /// Build a Cesium quantized-mesh terrain pyramid (EPSG:4326 TMS) with layer.json.
    #[command(allow_negative_numbers = true)]
    Tiles(TilesArgs),
    /// Serve a directory (a terrain pyramid) over HTTP on 127.0.0.1, for CesiumJS.
    #[command(allow_negative_numbers = true)]
    Serve(ServeArgs),
}

#[derive(Debug, Args)]
pub struct TilesArgs {
    /// Any georeferenced raster GDAL can read, in any CRS (reprojected to EPSG:4326).
    pub input: PathBuf,
    /// Output directory, new or empty: {z}/{x}/{y}.terrain and layer.json, moved into place
    /// whole when done.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Band to read (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// Coarsest level written.
    #[arg(long, default_value_t = 0)]
    pub min_zoom: u8,
    /// Finest level (default: where the tile sample spacing reaches the input's).
    #[arg(long)]
    pub max_zoom: Option<u8>,
    /// Bound per tile = Q x 77067.34 m / 2^level (Cesium's geometric error).
    #[arg(long, default_value_t = 1.0)]
    pub quality: f64,
    /// Add oct-encoded vertex normals (octvertexnormals extension).
    #[arg(long)]
    pub normals: bool,
    /// Add the metadata extension at levels 0, 10, 20 and metadataAvailability.
    #[arg(long)]
    pub metadata: bool,
    /// Write tiles uncompressed (by default they are gzipped; serve them with
    /// Content-Encoding: gzip).
    #[arg(long)]
    pub no_gzip: bool,
    /// Worker threads, at most 1024 (default: all cores).
    #[arg(long, default_value_t = 0, value_parser = threads_or_all)]
    pub threads: usize,
    /// Write the per-level report (bounds, measured error, tiles, bytes) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// No per-level lines or summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct ServeArgs {
    /// The directory to serve (made by `tinsmith tiles`).
    pub dir: PathBuf,
    /// Port on 127.0.0.1 (0 picks a free one; the address is printed).
    #[arg(long, default_value_t = 8000)]
    pub port: u16,
    /// Stop after this many requests (for tests).
    #[arg(long, hide = true)]
    pub max_requests: Option<u64>,
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Any raster GDAL can read.
    pub input: PathBuf,
    /// Band to describe (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// No progress line on stderr while the samples are scanned.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Args)]
pub struct MeshArgs {
    /// Any single-band raster GDAL can read (GeoTIFF, ESRI ASCII, HGT, VRT, PNG...).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.ply, .obj, .stl, .glb, .geojson,
    /// .fgb, .xml or .landxml for LandXML) unless --format names it. Optional with --per-tile.
    #[arg(short, long, required_unless_present = "per_tile")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub export: ExportArgs,
    /// Largest allowed |sample - TIN| at any valid sample, in data units. Required unless
    /// --max-triangles or --max-vertices is given.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true,
          required_unless_present_any = ["max_triangles", "max_vertices"])]
    pub max_error: Option<f64>,
    /// Decimate until at most N triangles remain (greedy order), then report the verified
    /// max error.
    #[arg(long, value_name = "N")]
    pub max_triangles: Option<usize>,
    /// Decimate until at most N vertices remain (greedy order).
    #[arg(long, value_name = "N")]
    pub max_vertices: Option<usize>,
    /// Band to read (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
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
    /// Samples per tile side, shared row and column included: a raster wider or taller
    /// than this is meshed tile by tile (in parallel, in bounded memory).
    #[arg(long, value_name = "N", default_value_t = tinsmith_tile::DEFAULT_TILE_SIZE,
          value_parser = clap::value_parser!(u32).range(2..))]
    pub tile_size: u32,
    /// Worker threads for tiles, at most 1024 and no more than there are tiles; 0 (the
    /// default) for one per core, as in `tiles`.
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
    #[arg(long, value_name = "NAME", value_parser = crate::export::parse_format)]
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

#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// The raster the mesh was made from.
    pub input: PathBuf,
    /// The mesh to check (.ply, .obj, .stl, .glb, .geojson, .fgb, .xml, or any with
    /// --format); GeoJSON in WGS84 is transformed back to the raster's CRS.
    pub mesh: PathBuf,
    /// The mesh's format, whatever its extension: ply, obj, stl, glb, geojson, fgb,
    /// landxml (for a file written with `mesh --format`).
    #[arg(long, value_name = "NAME", value_parser = crate::export::parse_format)]
    pub format: Option<MeshFormat>,
    /// Fail (exit 1) when the measured error exceeds this.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true)]
    pub max_error: Option<f64>,
    /// Band the mesh was made from (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// The mesh holds (column, row, value) coordinates (it was written with --pixel-coords).
    #[arg(long)]
    pub pixel_coords: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("which_levels").required(true).args(["interval", "levels"])))]
pub struct ContourArgs {
    /// Any single-band raster GDAL can read.
    pub input: PathBuf,
    /// Output lines; the format follows the extension (.geojson, .json, .fgb). GeoJSON is
    /// in WGS84 longitude/latitude unless --geojson-source-crs.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Contour every multiple of this (plus --offset) within the raster's height range (the mesh file's with --mesh).
    #[arg(long, value_parser = parse_interval, allow_hyphen_values = true)]
    pub interval: Option<f64>,
    /// Shift of the --interval levels: levels are offset + k * interval.
    /// (Default 0.)
    #[arg(long, requires = "interval", value_parser = parse_finite, allow_hyphen_values = true)]
    pub offset: Option<f64>,
    /// Explicit levels, comma-separated (negative ones too: --levels -100,0,100).
    #[arg(long, value_delimiter = ',', value_parser = parse_finite, allow_hyphen_values = true, conflicts_with = "interval")]
    pub levels: Vec<f64>,
    /// Contour the TIN decimated within this error of every sample; 0 (default) contours
    /// the full grid.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true, conflicts_with = "mesh")]
    pub max_error: Option<f64>,
    /// Contour this TIN (any format `tinsmith mesh` writes, written from INPUT) instead.
    #[arg(long, value_name = "MESH")]
    pub mesh: Option<PathBuf>,
    /// The --mesh file's format, whatever its extension: ply, obj, stl, glb, geojson, fgb,
    /// landxml.
    #[arg(long, value_name = "NAME", requires = "mesh", value_parser = crate::export::parse_format)]
    pub mesh_format: Option<MeshFormat>,
    /// Simplify each line (Douglas-Peucker) within this distance, in the output's map
    /// units (pixels with --pixel-coords): lines move up to D sideways and are no longer
    /// exact contours of the TIN.
    #[arg(long, value_name = "D", value_parser = parse_interval, allow_hyphen_values = true)]
    pub simplify: Option<f64>,
    /// Band to read (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// Write (column, row) coordinates; read --mesh as written with --pixel-coords.
    #[arg(long)]
    pub pixel_coords: bool,
    /// GeoJSON only: keep the raster's CRS (with a "crs" member and a note) instead of
    /// reprojecting to WGS84 longitude/latitude as RFC 7946 wants.
    #[arg(long)]
    pub geojson_source_crs: bool,
    /// Samples per tile side: with --max-error > 0, a raster wider or taller than this is
    /// decimated tile by tile (in parallel, reading a window at a time), as `tinsmith mesh`
    /// does; each tile is contoured as it is finished and its lines are joined to its
    /// neighbours' (the lines of the welded TIN, which is never held).
    #[arg(long, value_name = "N", default_value_t = tinsmith_tile::DEFAULT_TILE_SIZE,
          value_parser = clap::value_parser!(u32).range(2..))]
    pub tile_size: u32,
    /// Worker threads for tiles, at most 1024 and no more than there are tiles; 0 (the
    /// default) for one per core, as in `tiles`.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=1024))]
    pub threads: Option<u32>,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ErrorModelArg {
    /// The paper's accumulated bounds above and below each triangle.
    Bounds,
    /// The true max |sample - plane| over the samples a candidate triangle covers.
    Exact,
}

impl MeshArgs {
    /// Whether decimation raises the vertex heights with these flags on a raster whose
    /// valid heights span `heights` (the core's rule,
    /// [`DecimationOptions::raises_vertex_heights`], on the options the flags give).
    pub fn raises_vertex_heights(&self, heights: Option<(f64, f64)>) -> bool {
        let max_abs = heights.map_or(0.0, |(lo, hi)| lo.abs().max(hi.abs()));
        let max_error = self.max_error.unwrap_or(f64::INFINITY);
        self.decimation_options(max_error, heights)
            .is_ok_and(|options| options.raises_vertex_heights(max_abs))
    }

    /// The decimation options the flags ask for, with `max_error` as the bound (the
    /// untiled path passes the bound less the output format's height rounding); contour
    /// levels from --contour-interval run over `heights`, the raster's valid range.
    pub fn decimation_options(
        &self,
        max_error: f64,
        heights: Option<(f64, f64)>,
    ) -> anyhow::Result<DecimationOptions> {
        let mut options = DecimationOptions::new(max_error)
            .with_selection(self.selection.into())
            .with_error_model(self.error_model.into())
            .with_order(self.order.into())
            .with_retriangulation(self.retriangulate.into())
            .with_initial_mesh(self.initial_mesh.into());
        options.dp_max_ring = self.dp_max_ring as usize;
        options.max_edge_length = self.max_edge_length;
        options.flip_rounds = self.flip_rounds;
        options.extend_rounds = self.extend_rounds;
        options.vertex_heights = self.vertex_heights.into();
        let count_target = self.max_triangles.is_some() || self.max_vertices.is_some();
        if count_target && (self.flip_rounds > 0 || self.extend_rounds > 0) {
            anyhow::bail!(
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

impl From<ErrorModelArg> for ErrorModel {
    fn from(m: ErrorModelArg) -> ErrorModel {
        match m {
            ErrorModelArg::Bounds => ErrorModel::Bounds,
            ErrorModelArg::Exact => ErrorModel::Exact,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum VertexHeightsArg {
    /// Every vertex at its sample's value.
    Samples,
    /// Each vertex raised above its sample by a hair: 2^-24 of (--max-error + the largest
    /// |height|), at most 1/64 of --max-error (exact model, no count target, no contour
    /// levels): fewer triangles on integer heights at small bounds.
    /// Vertices on the raster's edges (and tiles') stay at their samples.
    Raised,
}

impl From<VertexHeightsArg> for VertexHeights {
    fn from(h: VertexHeightsArg) -> VertexHeights {
        match h {
            VertexHeightsArg::Samples => VertexHeights::Samples,
            VertexHeightsArg::Raised => VertexHeights::Raised,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum OrderArg {
    /// The paper's row-major sweeps, repeated until nothing can be removed.
    Sweep,
    /// Smallest-error removal first (priority queue).
    Greedy,
}

impl From<OrderArg> for Order {
    fn from(o: OrderArg) -> Order {
        match o {
            OrderArg::Sweep => Order::Sweep,
            OrderArg::Greedy => Order::Greedy,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum InitialMeshArg {
    /// Two triangles per valid cell (the paper's start).
    Full,
    /// The coarsest right-triangulated network within the bound (measured exactly).
    Rtin,
    /// Rows or columns simplified as 1-D lines within the bound, zipped into triangles.
    Strips,
    /// Strips, or the RTIN where it is cheap to build and has fewer triangles; the RTIN
    /// with contour levels.
    Auto,
}

impl From<InitialMeshArg> for InitialMesh {
    fn from(m: InitialMeshArg) -> InitialMesh {
        match m {
            InitialMeshArg::Full => InitialMesh::Full,
            InitialMeshArg::Rtin => InitialMesh::Rtin,
            InitialMeshArg::Strips => InitialMesh::Strips,
            InitialMeshArg::Auto => InitialMesh::Auto,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum RetriangulateArg {
    /// The paper's greedy ear selection, with --selection.
    Ears,
    /// Min-max-error triangulation by dynamic programming (holes up to --dp-max-ring
    /// vertices; larger ones by ears).
    Dp,
}

impl From<RetriangulateArg> for Retriangulation {
    fn from(r: RetriangulateArg) -> Retriangulation {
        match r {
            RetriangulateArg::Ears => Retriangulation::Ears,
            RetriangulateArg::Dp => Retriangulation::Dp,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum SelectionArg {
    /// Least-introduced first, least-error on a dead end (the paper's choice).
    Hybrid,
    /// The candidate edge with the least error bound.
    MinError,
    /// The candidate edge that changes the surface least.
    MinIntroduced,
}

impl From<SelectionArg> for EdgeSelection {
    fn from(s: SelectionArg) -> EdgeSelection {
        match s {
            SelectionArg::Hybrid => EdgeSelection::Hybrid,
            SelectionArg::MinError => EdgeSelection::MinError,
            SelectionArg::MinIntroduced => EdgeSelection::MinIntroduced,
        }
    }
}

fn parse_max_error(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("must be a finite number >= 0, got {s}"));
    }
    Ok(positive_zero(v))
}

/// `v`, with -0 as 0 (so that reports, summaries and `elev` values never say "-0").
fn positive_zero(v: f64) -> f64 {
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

fn parse_interval(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v <= 0.0 {
        return Err(format!("must be a finite number > 0, got {s}"));
    }
    Ok(v)
}

fn parse_finite(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() {
        return Err(format!("must be a finite number, got {s}"));
    }
    Ok(positive_zero(v))
}

/// `--threads` of `tiles`: 0 (one per core) to 1024.
fn threads_or_all(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n <= 1024 => Ok(n),
        _ => Err(format!(
            "{s} is not a thread count from 0 (one per core) to 1024"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minus_zero_is_read_as_zero() {
        for parsed in [
            parse_max_error("-0"),
            parse_finite("-0"),
            parse_finite("-0.0"),
        ] {
            let v = parsed.expect("a number");
            assert!(v == 0.0 && v.is_sign_positive(), "{v}");
        }
        assert!(parse_max_error("-1").is_err());
        assert_eq!(parse_finite("-2.5"), Ok(-2.5));
    }
}
