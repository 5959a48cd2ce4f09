//! Command-line flags (clap), parsed into plain values the commands use.

mod contour;
mod mesh;
mod values;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::{PreviewJob, ServeOptions, VerifyJob};
use tinsmith_terrain::{TerrainOptions, TileFormat};
use values::TilingArg;

pub use contour::ContourArgs;
pub use mesh::MeshArgs;

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
    Mesh(Box<MeshArgs>),
    /// Measure a TIN's true error against its raster at every valid sample.
    #[command(allow_negative_numbers = true)]
    Verify(VerifyArgs),
    /// Contour lines of the raster's TIN (decimated within --max-error, or given).
    #[command(allow_negative_numbers = true)]
    Contour(ContourArgs),
    /// Build a Cesium quantized-mesh terrain pyramid (EPSG:4326 TMS) with layer.json.
    #[command(allow_negative_numbers = true)]
    Tiles(TilesArgs),
    /// Serve a terrain pyramid (directory or MBTiles) over HTTP on 127.0.0.1, for CesiumJS.
    #[command(allow_negative_numbers = true)]
    Serve(ServeArgs),
    /// Draw a PNG of a raster's hillshade with its TIN's edges, or the TIN's signed error.
    #[command(allow_negative_numbers = true)]
    Preview(PreviewArgs),
}

#[derive(Debug, Args)]
pub struct PreviewArgs {
    /// The raster the mesh was made from.
    pub input: PathBuf,
    /// The mesh (any format `verify` reads); it must be a valid TIN of INPUT. Without it,
    /// INPUT is decimated first within --max-error (`mesh`'s other defaults).
    pub mesh: Option<PathBuf>,
    /// The PNG to write (replaced only by a complete one).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The picture's longer side in pixels (16 to 16384); each pixel shows the sample
    /// nearest its centre.
    #[arg(long, default_value_t = 1600)]
    pub size: u32,
    /// Draw the raster as a hillshade (gdaldem's default light). Without any of
    /// --hillshade, --wireframe, --error: hillshade and wireframe.
    #[arg(long)]
    pub hillshade: bool,
    /// Draw the TIN's edges.
    #[arg(long)]
    pub wireframe: bool,
    /// Colour each pixel by the signed error TIN - raster (blue below, red above), with a
    /// legend from -E to +E.
    #[arg(long)]
    pub error: bool,
    /// E for --error's colours (default: the largest error measured); without MESH, also
    /// the bound the TIN is decimated within.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true)]
    pub max_error: Option<f64>,
    /// The mesh's format, whatever its extension (as `verify --format`).
    #[arg(long, value_name = "NAME", value_parser = tinsmith_pipeline::parse_format)]
    pub format: Option<MeshFormat>,
    /// Band the mesh was made from (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// The mesh holds (column, row, value) coordinates (it was written with --pixel-coords).
    #[arg(long)]
    pub pixel_coords: bool,
    /// The mesh was made with `mesh --vertical-datum DATUM`: read the band's heights the
    /// same way.
    #[arg(long, value_name = "DATUM", value_parser = mesh::parse_datum)]
    pub vertical_datum: Option<tinsmith_raster::VerticalDatum>,
}

impl PreviewArgs {
    /// The job these flags ask for.
    pub fn job(&self) -> PreviewJob {
        let mesh = self.mesh.clone().unwrap_or_default();
        let mut job = PreviewJob::new(&self.input, mesh, &self.output);
        let none = !(self.hillshade || self.wireframe || self.error);
        job.hillshade = self.hillshade || none;
        job.wireframe = self.wireframe || none;
        job.error = self.error;
        job.max_error = self.max_error;
        job.size = self.size;
        job.format = self.format;
        job.band = self.band;
        job.pixel_coords = self.pixel_coords;
        job.vertical_datum = self.vertical_datum.clone();
        job
    }
}

#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct TilesArgs {
    #[command(subcommand)]
    pub step: Option<TilesStep>,
    /// Any georeferenced raster GDAL can read, in any CRS (reprojected to EPSG:4326).
    #[arg(required = true)]
    pub input: Option<PathBuf>,
    /// Output directory, new or empty: {z}/{x}/{y}.terrain and layer.json, moved into place
    /// whole when done; or NAME.mbtiles (one file, written whole); or s3://bucket/prefix,
    /// gs://bucket/prefix, az://container/prefix (layer.json written last). With --shard,
    /// a directory or bucket every shard writes into.
    #[arg(short, long, required = true)]
    pub output: Option<PathBuf>,
    /// Build only shard I of N (I from 0 to N-1), balanced by valid samples, into OUTPUT
    /// shared by all shards, with a record of what it built; a re-run keeps the blocks
    /// already done. Then `tinsmith tiles merge OUTPUT`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<tinsmith_terrain::Shard>,
    /// Update the pyramid in OUTPUT in place from a changed INPUT: rebuild only the tiles
    /// whose data changed since it was built (its records under OUTPUT/tinsmith/), remove
    /// those that no longer have data, leave the rest untouched.
    #[arg(long, conflicts_with = "shard")]
    pub update: bool,
    /// Band to read (1-based).
    #[arg(long, default_value_t = 1)]
    pub band: usize,
    /// What INPUT's (and --base's) heights are above: egm96, egm2008 or a geoid grid file
    /// (heights are turned into the ellipsoidal heights CesiumJS draws, through PROJ), or
    /// ellipsoid (used as they are). Default: each raster's own vertical CRS, else the
    /// ellipsoid, with a note.
    #[arg(long, value_name = "DATUM")]
    pub vertical_datum: Option<String>,
    /// Add the water mask extension (CesiumJS's requestWaterMask): `sea-level` (INPUT's
    /// nodata is sea, and heights at or below 0 beside it), a raster of water (1) and land
    /// (0), or a polygon layer of water.
    #[arg(long, value_name = "SOURCE")]
    pub water: Option<String>,
    /// A raster under INPUT (several: a VRT of them), read where INPUT has no valid
    /// sample: beyond it and at its nodata. It adds its extent to the pyramid down to its
    /// own level (where the tile sample spacing reaches its resolution); finer levels
    /// cover INPUT's extent only. Its heights are above --vertical-datum, else its own
    /// vertical CRS.
    #[arg(long, value_name = "RASTER")]
    pub base: Option<PathBuf>,
    /// Only the raster's data: no triangles beyond it, no root tile it does not reach
    /// (a layer to draw over another pyramid). Without it, the globe beyond the raster
    /// (and --base) is flat at height 0 on the ellipsoid, whatever --vertical-datum, and
    /// every root tile is written, so that a client shows the whole globe with the data
    /// on it.
    #[arg(long)]
    pub data_only: bool,
    /// How tiles divide the globe (layer.json's projection).
    #[arg(long, value_enum, default_value_t = TilingArg::Geographic)]
    pub tiling: TilingArg,
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
    /// Tile format: quantized-mesh (CesiumTerrainProvider), or 3dtiles: 3D Tiles 1.1
    /// terrain for Cesium3DTilesTerrainProvider (tileset.json, implicit subtrees, one
    /// uncompressed GLB per tile with CESIUM_tile_edges, water masks as PNG property
    /// textures), the same tiles, whole globe from level 0, into a directory.
    #[arg(long, value_name = "NAME", default_value = "quantized-mesh", value_parser = parse_tile_format)]
    pub format: TileFormat,
    /// Worker threads, at most 1024 (default: all cores); no more are started than there
    /// are cores.
    #[arg(long, default_value_t = 0, value_parser = threads_or_all)]
    pub threads: usize,
    /// Write the per-level report (bounds, measured error, tiles, bytes) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// No per-level lines or summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--format` of `tiles`.
fn parse_tile_format(name: &str) -> Result<TileFormat, String> {
    [TileFormat::QuantizedMesh, TileFormat::ThreeDTiles]
        .into_iter()
        .find(|f| f.label() == name)
        .ok_or_else(|| format!("unknown tile format {name:?}: quantized-mesh or 3dtiles"))
}

/// A step of a pyramid built in shards.
#[derive(Debug, Subcommand)]
pub enum TilesStep {
    /// Finish a pyramid built with --shard: check that every shard of one plan is there,
    /// build the levels above the shards' blocks, write layer.json last.
    Merge(MergeArgs),
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The directory the shards wrote into.
    pub dir: PathBuf,
    /// Worker threads, at most 1024 (default: all cores); no more are started than there
    /// are cores.
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
    /// The pyramid to serve: its directory, or an MBTiles file holding it.
    pub path: PathBuf,
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
pub struct VerifyArgs {
    /// The raster the mesh was made from, or its points (.las, .laz, .xyz/.csv/.txt) or
    /// TIN (.ply, .obj, .xml, .fgb): every point or vertex is measured against the mesh.
    pub input: PathBuf,
    /// The mesh to check (.ply, .obj, .stl, .glb, .geojson, .fgb, .xml, or any with
    /// --format); GeoJSON in WGS84 is transformed back to the raster's CRS.
    pub mesh: PathBuf,
    /// The mesh's format, whatever its extension: ply, obj, stl, glb, geojson, fgb,
    /// landxml (for a file written with `mesh --format`).
    #[arg(long, value_name = "NAME", value_parser = tinsmith_pipeline::parse_format)]
    pub format: Option<MeshFormat>,
    /// Fail (exit 1) when the measured error exceeds this. With --bands, one bound for
    /// every band or a comma-separated bound per band.
    #[arg(long, value_parser = parse_max_error, allow_hyphen_values = true,
          value_delimiter = ',', num_args = 1)]
    pub max_error: Vec<f64>,
    /// Band the mesh was made from (1-based).
    #[arg(long, default_value_t = 1, conflicts_with = "bands")]
    pub band: usize,
    /// The bands a `mesh --bands` mesh was made from: the first (or --height-band) against
    /// the mesh's heights, each other against the PLY property (glTF attribute) of its
    /// name, each within its --max-error, over the domain where every band is valid.
    #[arg(long, value_delimiter = ',', num_args = 1, value_name = "B,B,...")]
    pub bands: Vec<usize>,
    #[command(flatten)]
    pub variables: mesh::VariableArgs,
    /// The mesh holds (column, row, value) coordinates (it was written with --pixel-coords).
    #[arg(long)]
    pub pixel_coords: bool,
    /// The mesh was made with `mesh --vertical-datum DATUM`: measure it against the
    /// band's heights converted the same way.
    #[arg(long, value_name = "DATUM", value_parser = mesh::parse_datum)]
    pub vertical_datum: Option<tinsmith_raster::VerticalDatum>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub points: mesh::PointArgs,
}

impl VerifyArgs {
    /// The job these flags ask for; fails when --bands, --max-error and --height-band
    /// do not fit together.
    pub fn job(&self) -> tinsmith_pipeline::Result<VerifyJob> {
        let mut job = VerifyJob::new(&self.input, &self.mesh);
        job.format = self.format;
        let (band, max_error, variables) =
            self.variables
                .resolve(&self.input, self.band, &self.bands, &self.max_error)?;
        job.max_error = max_error;
        job.band = band;
        job.variables = variables;
        job.pixel_coords = self.pixel_coords;
        job.vertical_datum = self.vertical_datum.clone();
        Ok(job)
    }
}

impl TilesArgs {
    /// The pyramid's options these flags ask for, within `memory_limit` bytes.
    pub fn options(&self, memory_limit: Option<u64>) -> TerrainOptions {
        TerrainOptions {
            band: self.band,
            min_zoom: self.min_zoom,
            max_zoom: self.max_zoom,
            quality: self.quality,
            normals: self.normals,
            metadata: self.metadata,
            gzip: !self.no_gzip,
            threads: self.threads,
            memory_limit,
            update: self.update,
            vertical_datum: tinsmith_raster::VerticalDatum::Ellipsoid,
            water: None,
            whole_globe: !self.data_only,
            format: self.format,
            tiling: self.tiling.into(),
            base: None,
        }
    }
}

impl ServeArgs {
    /// What these flags ask to serve.
    pub fn options(&self) -> ServeOptions {
        ServeOptions {
            path: self.path.clone(),
            port: self.port,
            max_requests: self.max_requests,
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
