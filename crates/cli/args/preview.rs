//! The flags of `tinsmith preview`, parsed into a [`PreviewJob`].

use std::path::PathBuf;

use clap::Args;
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::PreviewJob;

use super::mesh::parse_datum;
use super::numbers::parse_max_error;

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
    #[arg(long, value_name = "DATUM", value_parser = parse_datum)]
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
