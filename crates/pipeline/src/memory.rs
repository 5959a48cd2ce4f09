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
/// available ([`available_bytes`]); passes when that cannot be read.
pub fn check_fits(needed: u64, refusal: impl FnOnce(f64, f64) -> String) -> Result<()> {
    match available_bytes() {
        Some(available) if needed > available => {
            bail!("{}", refusal(needed as f64 / 1e9, available as f64 / 1e9))
        }
        _ => Ok(()),
    }
}

/// The memory this process can still take, in bytes: the least of the system's
/// `MemAvailable` (`/proc/meminfo`), the room left under each memory cgroup limit it runs
/// in (a container's; v1 or v2, ancestors included) and under its address-space and data
/// `ulimit`s. `None` when none of them can be read.
pub fn available_bytes() -> Option<u64> {
    [
        meminfo_available(),
        cgroup_room(),
        rlimit_room(libc::RLIMIT_AS, "VmSize:"),
        rlimit_room(libc::RLIMIT_DATA, "VmData:"),
    ]
    .into_iter()
    .flatten()
    .min()
}

/// `MemAvailable` from `/proc/meminfo`, in bytes.
fn meminfo_available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    kib_field(&meminfo, "MemAvailable:")
}

/// The value of a `Name:   123 kB` line of a `/proc` file, in bytes.
fn kib_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// Room under a resource limit of this process: the soft limit less what it uses now
/// (`usage`, a field of `/proc/self/status`); `None` when unlimited.
#[allow(unsafe_code)]
fn rlimit_room(resource: libc::__rlimit_resource_t, usage: &str) -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given.
    if unsafe { libc::getrlimit(resource, &mut limit) } != 0
        || limit.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let used = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| kib_field(&status, usage))
        .unwrap_or(0);
    Some(limit.rlim_cur.saturating_sub(used))
}

/// Room under the memory limits of this process's cgroup and its ancestors: the least of
/// limit less usage (cgroup v2 `memory.max`/`memory.current`, v1
/// `memory.limit_in_bytes`/`memory.usage_in_bytes`), usage not counting the inactive file
/// cache the kernel reclaims first (`inactive_file`, v1 `total_inactive_file`, in
/// `memory.stat`: reading a large raster fills it); `None` when no limit is set or
/// readable.
fn cgroup_room() -> Option<u64> {
    let membership = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let (root, path, files) = cgroup_of(&membership)?;
    let mut room: Option<u64> = None;
    let mut dir = std::path::PathBuf::from(root).join(path.trim_start_matches('/'));
    loop {
        let read = |name: &str| -> Option<u64> {
            std::fs::read_to_string(dir.join(name))
                .ok()?
                .trim()
                .parse()
                .ok()
        };
        // v1 writes "no limit" as a huge number (about 2^63), v2 as "max" (no parse).
        if let (Some(limit), Some(usage)) = (read(files.0), read(files.1)) {
            if limit < 1 << 60 {
                let stat = std::fs::read_to_string(dir.join("memory.stat")).unwrap_or_default();
                let reclaimable = stat_field(&stat, "total_inactive_file")
                    .or_else(|| stat_field(&stat, "inactive_file"))
                    .unwrap_or(0);
                let here = limit.saturating_sub(usage.saturating_sub(reclaimable));
                room = Some(room.map_or(here, |r| r.min(here)));
            }
        }
        if dir == Path::new(root) || !dir.pop() {
            break;
        }
    }
    room
}

/// The value of a `name value` line of a cgroup's `memory.stat`.
fn stat_field(stat: &str, name: &str) -> Option<u64> {
    stat.lines().find_map(|line| {
        let (key, value) = line.split_once(' ')?;
        (key == name).then(|| value.trim().parse().ok())?
    })
}

/// The cgroup mount, this process's path below it and the limit and usage file names, from
/// `/proc/self/cgroup`: the v1 memory controller's line (`N:memory:/path`, possibly with
/// other controllers), else the v2 unified line (`0::/path`).
fn cgroup_of(membership: &str) -> Option<(&'static str, &str, (&'static str, &'static str))> {
    let mut unified = None;
    for line in membership.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        if controllers.split(',').any(|c| c == "memory") {
            return Some((
                "/sys/fs/cgroup/memory",
                path,
                ("memory.limit_in_bytes", "memory.usage_in_bytes"),
            ));
        }
        if controllers.is_empty() {
            unified = Some(path);
        }
    }
    unified.map(|path| ("/sys/fs/cgroup", path, ("memory.max", "memory.current")))
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

    #[test]
    fn cgroup_v1_memory_line_wins_over_the_unified_one() {
        let v1 = "9:name=systemd:/\n4:cpu,memory:/box/job\n0::/\n";
        let (root, path, files) = cgroup_of(v1).expect("a memory cgroup");
        assert_eq!(
            (root, path, files.0),
            ("/sys/fs/cgroup/memory", "/box/job", "memory.limit_in_bytes")
        );
        let (root, path, files) = cgroup_of("0::/user.slice/app\n").expect("v2");
        assert_eq!(
            (root, path, files.0),
            ("/sys/fs/cgroup", "/user.slice/app", "memory.max")
        );
        assert!(cgroup_of("3:cpuset:/\n").is_none());
    }

    #[test]
    fn memory_stat_fields() {
        let v1 = "cache 10\ninactive_file 7\ntotal_cache 30\ntotal_inactive_file 21\n";
        assert_eq!(stat_field(v1, "total_inactive_file"), Some(21));
        assert_eq!(stat_field(v1, "inactive_file"), Some(7));
        assert_eq!(stat_field("anon 5\n", "inactive_file"), None);
    }

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

    #[test]
    fn kib_fields_are_bytes() {
        let status = "Name:\ttinsmith\nVmSize:\t  123456 kB\nVmData:\t 42 kB\n";
        assert_eq!(kib_field(status, "VmSize:"), Some(123_456 * 1024));
        assert_eq!(kib_field(status, "VmData:"), Some(42 * 1024));
        assert_eq!(kib_field(status, "VmRSS:"), None);
    }
}
