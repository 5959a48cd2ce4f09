//! The flags of `tinsmith verify`, parsed into a [`VerifyJob`].

use std::path::PathBuf;

use clap::Args;
use tinsmith_formats::MeshFormat;
use tinsmith_pipeline::VerifyJob;

use super::mesh::parse_datum;
use super::numbers::parse_max_error;
use super::{PointArgs, VariableArgs};

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
    pub variables: VariableArgs,
    /// The mesh holds (column, row, value) coordinates (it was written with --pixel-coords).
    #[arg(long)]
    pub pixel_coords: bool,
    /// The mesh was made with `mesh --vertical-datum DATUM`: measure it against the
    /// band's heights converted the same way.
    #[arg(long, value_name = "DATUM", value_parser = parse_datum)]
    pub vertical_datum: Option<tinsmith_raster::VerticalDatum>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub points: PointArgs,
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
