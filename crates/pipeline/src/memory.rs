//! Whether a whole-raster run fits in memory. Count targets (`--max-triangles`,
//! `--max-vertices`), contouring the full grid, `contour --mesh` and `verify` hold the
//! whole raster (and a mesh) at once; on a raster too large for the machine they would be
//! killed partway, so they are refused up front with the estimate instead.

use std::path::Path;

use crate::error::bail;
use crate::Result;

/// What a whole-raster run holds, per raster sample and in all (measured on ETOPO5,
/// 9.3 M samples; rounded up).
#[derive(Debug, Clone, Copy)]
pub struct Need {
    /// Bytes per sample: 50 for a count target (raster as `f64`, the RTIN's and the
    /// mesh's per-sample arrays, the verifier's; 47 measured, plus 2 for the runs of
    /// equal samples a flat-heavy grid keeps), 120 to contour the full
    /// grid (its TIN has two triangles per cell; 115 measured), 24 for `verify` and
    /// `contour --mesh` (18 and 21 measured).
    pub bytes_per_sample: u64,
    /// Bytes besides, such as a start mesh or a mesh file read in ([`mesh_file_memory`]).
    pub extra_bytes: u64,
}

pub use tinsmith_tiling::BYTES_PER_START_TRIANGLE;

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
    let samples = u64::from(width) * u64::from(height);
    let needed = samples
        .saturating_mul(need.bytes_per_sample)
        .saturating_add(need.extra_bytes);
    check_fits(needed, |needed, available| {
        format!(
            "{}: {what} needs the whole {width}x{height} raster in memory at once, about \
             {needed:.1} GB, and {available:.1} GB is available; {instead}",
            input.display()
        )
    })
}

/// Fails with `refusal(needed GB, available GB)` when `needed` bytes exceed the memory
/// available ([`tinsmith_tiling::available_bytes`]); passes when that cannot be read.
pub fn check_fits(needed: u64, refusal: impl FnOnce(f64, f64) -> String) -> Result<()> {
    match tinsmith_tiling::available_bytes() {
        Some(available) if needed > available => {
            bail!("{}", refusal(needed as f64 / 1e9, available as f64 / 1e9))
        }
        _ => Ok(()),
    }
}

/// The size of `path` in bytes, 0 when it cannot be read (the reader reports that).
pub fn file_bytes(path: &Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}

/// The bytes the mesh file at `path` takes once read, with the verifier's per-triangle
/// arrays: its size times a factor per format. Measured
/// with `verify` on one ETOPO5 mesh (5.9 M triangles) written in every
/// format: the mesh took 385 MB read from PLY, OBJ, STL, glTF, GeoJSON or LandXML alike
/// (417 MB from FlatGeobuf), while the files weigh 18 (glTF) to 282 (GeoJSON) bytes a
/// triangle.
/// Each factor is the measured ratio rounded up, with room for files written more
/// compactly than tinsmith writes them (OBJ).
pub fn mesh_file_memory(path: &Path, format: tinsmith_formats::MeshFormat) -> u64 {
    use tinsmith_formats::MeshFormat;
    // Measured ratios: PLY 2.6, OBJ 1.36, STL 1.3, glTF 3.6, GeoJSON 0.23,
    // FlatGeobuf 0.32, LandXML 0.85.
    let (times, per) = match format {
        MeshFormat::Ply => (3, 1),
        MeshFormat::Obj => (2, 1),
        MeshFormat::Stl => (3, 2),
        MeshFormat::GeoJson => (3, 10),
        MeshFormat::Glb => (4, 1),
        MeshFormat::FlatGeobuf => (2, 5),
        MeshFormat::LandXml => (1, 1),
        _ => (2, 1),
    };
    file_bytes(path).saturating_mul(times) / per
}

/// The raster's `(width, height)`, without reading its samples.
pub fn raster_size(input: &Path, band: usize) -> Result<(u32, u32)> {
    let reader = tinsmith_raster::WindowReader::open(input, band)?;
    Ok((reader.width(), reader.height()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verifier held 65 bytes a triangle for a mesh read from any format (measured,
    /// see [`mesh_file_memory`]): the estimate covers that for files as tinsmith writes
    /// them, in every format.
    #[test]
    fn mesh_file_estimates_cover_the_measured_memory_per_triangle() {
        use tinsmith_formats::{MeshFormat, MeshRef};
        // Over 65,536 vertices: glTF then stores 32-bit indices, as large meshes do.
        let n = 260u32;
        let vertices: Vec<[f64; 3]> = (0..n * n)
            .map(|i| {
                let (x, y) = (f64::from(i % n), f64::from(i / n));
                [
                    500_000.0 + 30.0 * x,
                    4_100_000.0 - 30.0 * y,
                    1234.5 + (x * y).sqrt(),
                ]
            })
            .collect();
        let mut triangles = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let i = y * n + x;
                triangles.push([i, i + n, i + 1]);
                triangles.push([i + 1, i + n, i + n + 1]);
            }
        }
        let dir = tempfile::tempdir().unwrap();
        for format in MeshFormat::ALL {
            let path = dir.path().join(format!("mesh.{}", format.extension()));
            let mesh = MeshRef::new(&vertices, &triangles);
            tinsmith_formats::write_mesh(&path, format, mesh).unwrap();
            let estimate = mesh_file_memory(&path, format);
            assert!(
                estimate >= 65 * triangles.len() as u64,
                "{format:?}: {estimate} bytes for {} triangles",
                triangles.len()
            );
        }
    }
}
