//! GDAL's block cache: how much of the rasters read GDAL keeps in memory, process-wide.

/// Caps GDAL's raster block cache at `megabytes` for the whole process, unless the user
/// chose a size with the `GDAL_CACHEMAX` environment variable (which is then left alone);
/// returns whether the cap was set.
///
/// GDAL's default is 5 % of the machine's memory. Reading a large raster window by window
/// (or scanning it with [`crate::open_info`]) would fill all of it with blocks that are
/// never read again, which shows up as resident memory; a tiled reader needs only the
/// blocks of the current row of tiles. Call this once from a binary, before the first
/// raster is read: GDAL reads the setting when its cache is first used.
pub fn limit_block_cache(megabytes: u64) -> bool {
    if std::env::var_os("GDAL_CACHEMAX").is_some() {
        return false;
    }
    // GDAL reads values below 100000 as megabytes.
    gdal::config::set_config_option("GDAL_CACHEMAX", &megabytes.min(99_999).to_string()).is_ok()
}
