//! The statistics scan every tiled run starts with, with its progress.

use std::path::Path;

use crate::Feedback;

/// Scans band `band` of `input` for its statistics ([`tinsmith_raster::open_info`]: a full
/// read, long on a large raster), telling `feedback` the share of rows done.
pub fn scan_raster(
    input: &Path,
    band: usize,
    feedback: &dyn Feedback,
) -> tinsmith_raster::Result<tinsmith_raster::RasterInfo> {
    let name = input.display();
    let info = tinsmith_raster::open_info_with_progress(input, band, &mut |done, rows| {
        feedback.status(&format!(
            "{name}: scanning, {} % of the rows",
            done * 100 / rows.max(1)
        ));
    });
    feedback.clear_status();
    info
}
