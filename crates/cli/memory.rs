//! Whether a whole-raster run fits in memory: count targets (`--max-triangles`,
//! `--max-vertices`) need the whole raster at once, so on a raster too large for the
//! machine they would be killed by the kernel partway; they are refused up front instead.

use std::path::Path;

use anyhow::{bail, Result};

/// Bytes per raster sample of a count-target run besides its start mesh: the raster as
/// `f64`, the RTIN's and the mesh's per-sample arrays and the verifier's. Measured 47 on
/// ETOPO5 (9.3 M samples, 1 M triangles: 437 MB in all); rounded up.
const BYTES_PER_SAMPLE: u64 = 48;

/// Bytes per triangle of the start mesh (slots, links, bounds, output), rounded up.
const BYTES_PER_TRIANGLE: u64 = 40;

/// Fails, naming `input`, when a count-target run on a `width` x `height` raster for
/// `target_triangles` (the start mesh has up to four times as many, at most two per sample)
/// would need more memory than the system reports available. Passes when the system does
/// not say (no `/proc/meminfo`).
pub fn check_whole_raster_fits(
    input: &Path,
    width: usize,
    height: usize,
    target_triangles: u64,
) -> Result<()> {
    let Some(available) = available_bytes() else {
        return Ok(());
    };
    let samples = (width as u64).saturating_mul(height as u64);
    let start_triangles = target_triangles
        .saturating_mul(4)
        .min(samples.saturating_mul(2));
    let needed = samples
        .saturating_mul(BYTES_PER_SAMPLE)
        .saturating_add(start_triangles.saturating_mul(BYTES_PER_TRIANGLE));
    if needed > available {
        let gb = |bytes: u64| bytes as f64 / 1e9;
        bail!(
            "{}: --max-triangles and --max-vertices need the whole {width}x{height} raster in \
             memory at once, about {:.1} GB, and {:.1} GB is available; give --max-error \
             instead (decimated tile by tile, in bounded memory)",
            input.display(),
            gb(needed),
            gb(available)
        );
    }
    Ok(())
}

/// `MemAvailable` from `/proc/meminfo`, in bytes.
fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}
