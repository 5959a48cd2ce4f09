//! The statistics scan every tiled run starts with, with its progress.

use std::path::Path;

use crate::Feedback;

/// Scans band `band` of `input` for its statistics ([`tinsmith_raster::open_info`]: a full
/// read, long on a large raster), telling `feedback` the share of rows done.
/// With `datum`, the heights scanned are those converted from it to heights above the
/// ellipsoid ([`tinsmith_raster::open_info_on`]).
pub fn scan_raster(
    input: &Path,
    band: usize,
    datum: Option<&tinsmith_raster::VerticalDatum>,
    feedback: &dyn Feedback,
) -> tinsmith_raster::Result<tinsmith_raster::RasterInfo> {
    let name = input.display();
    let datum = datum.unwrap_or(&tinsmith_raster::VerticalDatum::Ellipsoid);
    let info = tinsmith_raster::open_info_on(input, band, datum, &mut |done, rows| {
        feedback.status(&format!(
            "{name}: scanning, {} % of the rows",
            done * 100 / rows.max(1)
        ));
    });
    feedback.clear_status();
    info
}
