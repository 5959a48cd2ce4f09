//! Command-line flags (clap), parsed into plain values the commands use.

mod contour;
mod mesh;
mod numbers;
mod points;
mod preview;
mod tiles;
mod values;
mod variables;
mod verify;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

pub use contour::ContourArgs;
pub use mesh::MeshArgs;
pub use points::PointArgs;
pub use preview::PreviewArgs;
pub use tiles::{ServeArgs, TilesArgs, TilesStep};
pub use variables::VariableArgs;
pub use verify::VerifyArgs;

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
