//! `--height-band`, `--attributes` and their bounds: the variables `mesh` and `verify` take besides `--bands`.

use clap::Args;

use super::numbers::parse_max_error;

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
