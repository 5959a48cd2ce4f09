//! Whether a whole-raster run fits in memory. Count targets (`--max-triangles`,
//! `--max-vertices`), contouring the full grid, `contour --mesh` and `verify` hold the
//! whole raster (and a mesh) at once; on a raster too large for the machine they would be
//! killed partway, so they are refused up front with the estimate instead.

use std::path::Path;

use anyhow::{bail, Result};

/// What a whole-raster run holds, per raster sample and in all (measured on ETOPO5,
/// 9.3 M samples, session 4; rounded up).
#[derive(Debug, Clone, Copy)]
pub struct Need {
    /// Bytes per sample: 48 for a count target (raster as `f64`, the RTIN's and the
    /// mesh's per-sample arrays, the verifier's; 47 measured), 120 to contour the full
    /// grid (its TIN has two triangles per cell; 115 measured), 24 for `verify` and
    /// `contour --mesh` (18 and 21 measured).
    pub bytes_per_sample: u64,
    /// Bytes besides, such as a start mesh or a mesh file read in.
    pub extra_bytes: u64,
}

/// Bytes per triangle of a count target's start mesh (slots, links, bounds, output).
pub const BYTES_PER_START_TRIANGLE: u64 = 40;

/// Fails, naming `input`, when holding a `width` x `height` raster as `need` says would
/// take more memory than the system reports available; `what` names the run and
/// `instead` what to do about it. Passes when the system does not say (no
/// `/proc/meminfo`).
pub fn check_whole_raster_fits(
    input: &Path,
    (width, height): (u32, u32),
    need: Need,
    what: &str,
    instead: &str,
) -> Result<()> {
    let Some(available) = available_bytes() else {
        return Ok(());
    };
    let samples = u64::from(width) * u64::from(height);
    let needed = samples
        .saturating_mul(need.bytes_per_sample)
        .saturating_add(need.extra_bytes);
    if needed > available {
        let gb = |bytes: u64| bytes as f64 / 1e9;
        bail!(
            "{}: {what} needs the whole {width}x{height} raster in memory at once, about \
             {:.1} GB, and {:.1} GB is available; {instead}",
            input.display(),
            gb(needed),
            gb(available)
        );
    }
    Ok(())
}

/// `MemAvailable` from `/proc/meminfo`, in bytes.
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The size of `path` in bytes, 0 when it cannot be read (the reader reports that).
pub fn file_bytes(path: &Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}

/// The raster's `(width, height)`, without reading its samples.
pub fn raster_size(input: &Path, band: usize) -> Result<(u32, u32)> {
    let reader = tinsmith_raster::WindowReader::open(input, band)?;
    Ok((reader.width(), reader.height()))
}
