//! The flags of `tinsmith tiles`, `tiles merge` and `serve`.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use tinsmith_pipeline::ServeOptions;
use tinsmith_terrain::{TerrainOptions, TileFormat};

use super::numbers::threads_or_all;
use super::values::TilingArg;

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
    #[command(flatten)]
    pub run: RunArgs,
}

/// The flags of a pyramid's run that `tiles` and `tiles merge` share.
#[derive(Debug, Args)]
pub struct RunArgs {
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
    #[command(flatten)]
    pub run: RunArgs,
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
            threads: self.run.threads,
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
