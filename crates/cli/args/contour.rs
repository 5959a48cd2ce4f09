//! The flags of `tinsmith contour`, parsed into a [`ContourJob`].

use std::path::PathBuf;

use clap::{ArgGroup, Args};
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::ContourJob;

use super::numbers::{parse_finite, parse_interval, parse_max_error};

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
    #[arg(long, value_name = "NAME", requires = "mesh", value_parser = tinsmith_pipeline::parse_format)]
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
    #[arg(long, value_name = "N", default_value_t = tinsmith_pipeline::DEFAULT_TILE_SIZE,
          value_parser = clap::value_parser!(u32).range(2..))]
    pub tile_size: u32,
    /// Worker threads for tiles, at most 1024; 0 (the default) for one per core, as in
    /// `tiles`. No more are started than there are cores or tiles: more would only wait,
    /// each with its tiles in memory.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=1024))]
    pub threads: Option<u32>,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl ContourArgs {
    /// The job these flags ask for.
    pub fn job(&self) -> ContourJob {
        let mut job = ContourJob::new(&self.input, &self.output);
        job.interval = self.interval;
        job.offset = self.offset;
        job.levels = self.levels.clone();
        job.max_error = self.max_error;
        job.mesh = self.mesh.clone();
        job.mesh_format = self.mesh_format;
        job.simplify = self.simplify;
        job.band = self.band;
        job.pixel_coords = self.pixel_coords;
        job.geojson_source_crs = self.geojson_source_crs;
        job.tile_size = self.tile_size;
        job.threads = self.threads;
        job
    }
}
