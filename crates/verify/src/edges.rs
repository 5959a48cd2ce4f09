//! Check 6, conformity: every edge inside the domain is shared by exactly two triangles,
//! one on each side, and every edge used by one triangle lies on the domain's outline with
//! the domain on that triangle's side. Together with the area check this rules out holes
//! balanced by overlaps, cracks, T-junctions and repeated vertices with other heights.

use rustc_hash::FxHashMap;

use crate::predicates::orient;
use crate::problems::{Kind, ProblemLog};
use crate::{GridRef, MeshRef, Report};

/// One side of one triangle: the edge between vertices `low < high` (welded ids), and on
/// which side of the directed line `low -> high` the triangle lies.
#[derive(Debug, Clone, Copy)]
struct Side {
    low: u32,
    high: u32,
    left: bool,
}

/// A side stored under its `low` vertex: `high` and `left` packed as `high << 1 | left`,
/// so the integer order is the order by `(high, left)`. `u32` holds ids below 2^31 (4
/// bytes per side, where a [`Side`] takes 12: the sides are the verifier's largest array);
/// `u64` holds any.
trait PackedSide: Copy + Ord + Default {
    /// The largest number of vertices whose ids fit.
    const VERTICES: usize;
    fn pack(high: u32, left: bool) -> Self;
    fn high(self) -> u32;
    fn left(self) -> bool;
}

impl PackedSide for u32 {
    const VERTICES: usize = 1 << 31;
    fn pack(high: u32, left: bool) -> u32 {
        debug_assert!(high < 1 << 31);
        high << 1 | u32::from(left)
    }
    fn high(self) -> u32 {
        self >> 1
    }
    fn left(self) -> bool {
        self & 1 == 1
    }
}

impl PackedSide for u64 {
    const VERTICES: usize = usize::MAX;
    fn pack(high: u32, left: bool) -> u64 {
        u64::from(high) << 1 | u64::from(left)
    }
    fn high(self) -> u32 {
        (self >> 1) as u32
    }
    fn left(self) -> bool {
        self & 1 == 1
    }
}

/// Checks conformity over the `measured` triangles (non-degenerate, corners in the grid),
/// welding vertices that share a position and height first (formats without shared
/// vertices repeat them).
pub(crate) fn check_edges(
    grid: GridRef<'_>,
    mesh: MeshRef<'_>,
    measured: &[bool],
    report: &mut Report,
    log: &mut ProblemLog,
) {
    if mesh.positions.len() <= u32::VERTICES {
        check_packed_edges::<u32>(grid, mesh, measured, report, log);
    } else {
        check_packed_edges::<u64>(grid, mesh, measured, report, log);
    }
}

/// [`check_edges`] with sides packed in `K`, which must hold every vertex id.
fn check_packed_edges<K: PackedSide>(
    grid: GridRef<'_>,
    mesh: MeshRef<'_>,
    measured: &[bool],
    report: &mut Report,
    log: &mut ProblemLog,
) {
    debug_assert!(mesh.positions.len() <= K::VERTICES);
    let welded = welded_ids(mesh);
    let triangles = || {
        mesh.triangles
            .iter()
            .zip(measured)
            .filter(|(_, &m)| m)
            .map(|(corners, _)| corners.map(|v| welded[v as usize]))
    };
    let (start, sides) = sorted_by_edge::<K, _>(
        triangles().flat_map(|c| (0..3).map(move |k| c[k].min(c[(k + 1) % 3]))),
        || {
            triangles().flat_map(|c| {
                (0..3).map(move |k| {
                    let (a, b, r) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
                    let (low, high) = (a.min(b), a.max(b));
                    let [pl, ph, pr] = [low, high, r].map(|v| mesh.positions[v as usize]);
                    Side {
                        low,
                        high,
                        left: orient(pl, ph, pr) > 0,
                    }
                })
            })
        },
        mesh.positions.len(),
    );
    for (low, range) in start.windows(2).enumerate() {
        for group in sides[range[0]..range[1]].chunk_by(|a, b| a.high() == b.high()) {
            let [p, q] = [low, group[0].high() as usize].map(|v| mesh.positions[v]);
            match group {
                [one] => {
                    if !on_outline(grid, p, q, one.left()) {
                        report.open_edges += 1;
                        log.push(Kind::OpenEdge, || {
                            format!(
                                "edge ({}, {})-({}, {}) borders one triangle but is not on \
                                 the domain's outline (a hole, crack or T-junction)",
                                p[0], p[1], q[0], q[1]
                            )
                        });
                    }
                }
                [a, b] if a.left() != b.left() => {}
                _ => {
                    report.overlapping_edges += 1;
                    let left = group.iter().filter(|s| s.left()).count();
                    log.push(Kind::OverlappingEdge, || {
                        format!(
                            "edge ({}, {})-({}, {}) is shared by {} triangles, {} on one side \
                             (they overlap)",
                            p[0],
                            p[1],
                            q[0],
                            q[1],
                            group.len(),
                            left.max(group.len() - left)
                        )
                    });
                }
            }
        }
    }
}

/// Each vertex's id after welding: the first vertex with its position and height. When
/// the positions strictly increase in row-major order (as a TIN's vertices from the core
/// do), no two share a position and every vertex is its own id, without a hash map.
fn welded_ids(mesh: MeshRef<'_>) -> Vec<u32> {
    let n = mesh.positions.len() as u32;
    let row_major = |p: &[i64; 2]| (p[1], p[0]);
    if mesh
        .positions
        .windows(2)
        .all(|w| row_major(&w[0]) < row_major(&w[1]))
    {
        return (0..n).collect();
    }
    let mut ids: FxHashMap<([i64; 2], u64), u32> = FxHashMap::default();
    ids.reserve(mesh.positions.len());
    mesh.positions
        .iter()
        .zip(mesh.heights)
        .enumerate()
        // +0.0 and -0.0 are the same height.
        .map(|(v, (&p, z))| *ids.entry((p, (z + 0.0).to_bits())).or_insert(v as u32))
        .collect()
}

/// The sides `sides()` yields, grouped by `low` and ordered by `(high, left)` within each
/// group, given `lows` (their `low` ids, in any order, all below `vertices`): vertex `v`'s
/// sides are `sorted[start[v]..start[v + 1]]`. Counted by `low` in a first pass, placed in
/// a second, then each vertex's few sides sorted on their own: linear time, where a
/// comparison sort of all sides took a quarter of the verification, and one array of
/// packed sides, not an unsorted copy besides.
fn sorted_by_edge<K: PackedSide, I: Iterator<Item = Side>>(
    lows: impl Iterator<Item = u32>,
    sides: impl FnOnce() -> I,
    vertices: usize,
) -> (Vec<usize>, Vec<K>) {
    let mut start = vec![0usize; vertices + 1];
    for low in lows {
        start[low as usize + 1] += 1;
    }
    for v in 0..vertices {
        start[v + 1] += start[v];
    }
    let mut sorted = vec![K::default(); start[vertices]];
    for s in sides() {
        let at = &mut start[s.low as usize];
        sorted[*at] = K::pack(s.high, s.left);
        *at += 1;
    }
    // Each `start[v]` has moved on to where `v + 1`'s sides start: shift them back.
    for v in (0..vertices).rev() {
        start[v + 1] = start[v];
    }
    start[0] = 0;
    for range in start.windows(2) {
        sorted[range[0]..range[1]].sort_unstable();
    }
    (start, sorted)
}

/// Whether segment `p -> q` runs along the domain's outline with the domain on its left
/// (`left`) or right side: axis-parallel (the outline of a union of cells is), and at every
/// unit step the cell on that side is valid and the cell on the other side is not.
fn on_outline(grid: GridRef<'_>, p: [i64; 2], q: [i64; 2], left: bool) -> bool {
    let (dx, dy) = ((q[0] - p[0]).signum(), (q[1] - p[1]).signum());
    if dx != 0 && dy != 0 {
        return false;
    }
    let steps = (q[0] - p[0]).abs().max((q[1] - p[1]).abs());
    // The normal pointing to the left of the direction (dx, dy) in (x, y): (-dy, dx) has
    // orient(p, q, p + normal) > 0.
    let (nx, ny) = if left { (-dy, dx) } else { (dy, -dx) };
    (0..steps).all(|s| {
        let (x, y) = (p[0] + s * dx, p[1] + s * dy);
        // The unit segment (x, y) -> (x + dx, y + dy); the cells beside it have their
        // lowest corner at these positions.
        let (sx, sy) = (x.min(x + dx), y.min(y + dy));
        let (inner, outer) = if dx != 0 {
            ((sx, sy + ny.min(0)), (sx, sy - ny.max(0)))
        } else {
            ((sx + nx.min(0), sy), (sx - nx.max(0), sy))
        };
        cell_is_valid(grid, inner) && !cell_is_valid(grid, outer)
    })
}

/// Whether the cell with lowest corner `(x, y)` lies in the grid with four valid corners.
fn cell_is_valid(grid: GridRef<'_>, (x, y): (i64, i64)) -> bool {
    let inside = |x: i64, y: i64| {
        x >= 0 && y >= 0 && x < i64::from(grid.width) && y < i64::from(grid.height)
    };
    inside(x, y)
        && inside(x + 1, y + 1)
        && [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)]
            .iter()
            .all(|&(x, y)| grid.is_valid(x as u32, y as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_joins_equal_positions_and_heights_only() {
        let ids = |positions: &[[i64; 2]], heights: &[f64]| {
            welded_ids(MeshRef::new(positions, heights, &[]))
        };
        // Row-major and distinct: every vertex is its own id.
        assert_eq!(ids(&[[0, 0], [5, 0], [0, 1]], &[1.0, 2.0, 3.0]), [0, 1, 2]);
        // Out of row-major order, still distinct.
        assert_eq!(ids(&[[0, 1], [5, 0], [0, 0]], &[1.0, 2.0, 3.0]), [0, 1, 2]);
        // Repeated positions, even in row-major order, go through the welding.
        assert_eq!(ids(&[[0, 0], [0, 0], [1, 0]], &[1.0, 1.0, 2.0]), [0, 0, 2]);
        // Repeated positions: welded to the first with the same height (-0 = +0).
        assert_eq!(
            ids(
                &[[0, 0], [1, 0], [0, 0], [0, 0], [1, 0]],
                &[0.0, 2.0, -0.0, 7.0, 2.0]
            ),
            [0, 1, 0, 3, 1]
        );
    }

    #[test]
    fn counting_sort_orders_sides_as_a_full_sort() {
        // Deterministic LCG; few vertices, so that edges repeat and buckets are uneven.
        let mut state: u64 = 7;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % n) as u32
        };
        let vertices = 50;
        let sides: Vec<Side> = (0..2000)
            .map(|_| {
                let (a, b) = (next(vertices), next(vertices));
                Side {
                    low: a.min(b),
                    high: a.max(b),
                    left: next(2) == 1,
                }
            })
            .collect();
        let key = |s: &Side| (s.low, s.high, s.left);
        let mut expected = sides.clone();
        expected.sort_unstable_by_key(key);
        let expected: Vec<_> = expected.iter().map(key).collect();
        fn unpacked<K: PackedSide>(start: &[usize], sorted: &[K]) -> Vec<(u32, u32, bool)> {
            start
                .windows(2)
                .enumerate()
                .flat_map(|(low, r)| {
                    sorted[r[0]..r[1]]
                        .iter()
                        .map(move |s| (low as u32, s.high(), s.left()))
                })
                .collect()
        }
        let lows = || sides.iter().map(|s| s.low);
        let (start, got) =
            sorted_by_edge::<u32, _>(lows(), || sides.iter().copied(), vertices as usize);
        assert_eq!(unpacked(&start, &got), expected);
        let (start, got) =
            sorted_by_edge::<u64, _>(lows(), || sides.iter().copied(), vertices as usize);
        assert_eq!(unpacked(&start, &got), expected);
    }
}
