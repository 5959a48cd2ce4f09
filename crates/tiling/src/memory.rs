//! How much memory a run may still take, and what meshing a whole grid at once needs, so
//! that a run too large for the machine is refused before it allocates instead of killed
//! partway (the CLI's whole-raster runs, the Python package's arrays).

use std::path::Path;

/// Bytes per sample of meshing a whole grid in one piece (the grid as `f64`, the start
/// mesh, the decimator's and the verifier's per-sample arrays): 82 measured untiled on
/// ETOPO5 at ε = 1, more at smaller bounds; rounded up.
pub const WHOLE_GRID_BYTES_PER_SAMPLE: u64 = 120;

/// Bytes per sample of a count target (`max_triangles`, `max_vertices`): the grid as
/// `f64`, the RTIN's and the mesh's per-sample arrays, the verifier's (47 measured on
/// ETOPO5, plus 2 for the runs of equal samples a flat-heavy grid keeps); the start mesh
/// is counted apart ([`BYTES_PER_START_TRIANGLE`]).
pub const COUNT_TARGET_BYTES_PER_SAMPLE: u64 = 50;

/// Bytes per triangle of a count target's start mesh (slots, links, bounds, output).
pub const BYTES_PER_START_TRIANGLE: u64 = 40;

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

    #[test]
    fn kib_fields_are_bytes() {
        let status = "Name:\ttinsmith\nVmSize:\t  123456 kB\nVmData:\t 42 kB\n";
        assert_eq!(kib_field(status, "VmSize:"), Some(123_456 * 1024));
        assert_eq!(kib_field(status, "VmData:"), Some(42 * 1024));
        assert_eq!(kib_field(status, "VmRSS:"), None);
    }
}
