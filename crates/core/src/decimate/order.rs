//! The order vertices are tried in: the paper's row-major sweeps (§3.1), or smallest error
//! first (greedy, for count targets).

use std::collections::BinaryHeap;

use super::{Progress, Remover};
use crate::mesh::Mesh;

/// What the removal loops counted, for [`crate::DecimationReport`].
#[derive(Debug, Default)]
pub(super) struct Stats {
    pub(super) sweeps: usize,
    pub(super) attempts: usize,
    pub(super) removed: usize,
}

/// The paper's sweep, made cheap: a vertex whose star did not change since it last failed
/// would fail again, so each sweep visits only vertices whose star changed, in the same
/// row-major order a full sweep would. With `stop` (a count target and the vertices at the
/// start), it ends as soon as the count is reached.
pub(super) fn sweep(
    mesh: &mut Mesh<'_>,
    remover: &mut Remover<'_>,
    stats: &mut Stats,
    progress: &mut dyn FnMut(Progress),
    stop: Option<(Target, usize)>,
) {
    let n = mesh.vertex_slots();
    let mut queued = vec![false; n];
    // The sweep in which each vertex last got a large hole beside it (0: none yet).
    let mut beside_large_hole = vec![0u32; n];
    let width = mesh.grid_width();
    let mut this_sweep = AscendingQueue::new(n);
    let mut next_sweep: Vec<u32> = Vec::new();
    for v in 0..n as u32 {
        if mesh.contains_vertex(v) {
            queued[v as usize] = true;
            next_sweep.push(v);
        }
    }
    while !next_sweep.is_empty() {
        stats.sweeps += 1;
        for v in next_sweep.drain(..) {
            this_sweep.insert(v);
        }
        let mut sweep_size = this_sweep.len();
        let mut tried = 0usize;
        progress(Progress {
            sweep: stats.sweeps,
            sweep_fraction: 0.0,
            removed: stats.removed,
        });
        while let Some(v) = this_sweep.pop_min() {
            if beside_large_hole[v as usize] == stats.sweeps as u32 {
                next_sweep.push(v);
                continue;
            }
            queued[v as usize] = false;
            stats.attempts += 1;
            tried += 1;
            if stats.attempts.is_multiple_of(65_536) {
                let sweep_fraction = tried as f64 / sweep_size.max(tried) as f64;
                progress(Progress {
                    sweep: stats.sweeps,
                    sweep_fraction,
                    removed: stats.removed,
                });
            }
            if remover.plan(mesh, v).is_some() {
                remover.apply(mesh, v);
                stats.removed += 1;
                if stop
                    .is_some_and(|(target, initial)| target.reached(mesh, initial, stats.removed))
                {
                    return;
                }
                let large_hole = ring_box_area(&remover.star.ring, width) > LARGE_HOLE_BOX;
                for &u in &remover.star.ring {
                    if large_hole {
                        beside_large_hole[u as usize] = stats.sweeps as u32;
                    }
                    if !queued[u as usize] {
                        queued[u as usize] = true;
                        if u > v {
                            this_sweep.insert(u);
                            sweep_size += 1;
                        } else {
                            next_sweep.push(u);
                        }
                    }
                }
            }
        }
    }
}

/// The vertices around a removed vertex whose hole's bounding box covers more samples than
/// this wait for the next sweep. Where the ground is planar over large areas, removals in
/// one sweep otherwise chain: each one's star holds the triangles the last one made, so
/// the samples measured per removal grow with the chain (a 4000² tilted plane, untiled:
/// 155 s of decimation, 1.7 s with the wait). Waiting lets each sweep remove about every
/// other vertex there, so stars double per sweep instead. Holes this large are rare on real
/// DEMs: six of them at bounds 0.5 to 30 keep the same triangle counts to within 0.01 %,
/// except Fort Worth at 30 (61 triangles, now 68; docs/results.md, "Large holes").
const LARGE_HOLE_BOX: i64 = 128 * 128;

/// The area (in samples) of the bounding box of `ring`'s sample positions.
fn ring_box_area(ring: &[u32], width: usize) -> i64 {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &v in ring {
        let (x, y) = (v as usize % width, v as usize / width);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    (x1.saturating_sub(x0) as i64) * (y1.saturating_sub(y0) as i64)
}

/// A set of vertex slots taken out smallest first: a bit per slot and a cursor below which
/// no bit is set. In a sweep every insertion is above the slot last taken, so the cursor
/// only moves forward and both operations cost O(1) amortized (a heap costs O(log n)).
struct AscendingQueue {
    words: Vec<u64>,
    /// No bit is set in the words before this one.
    cursor: usize,
    len: usize,
}

impl AscendingQueue {
    fn new(slots: usize) -> AscendingQueue {
        AscendingQueue {
            words: vec![0; slots.div_ceil(64)],
            cursor: 0,
            len: 0,
        }
    }

    fn len(&self) -> usize {
        self.len
    }

    fn insert(&mut self, v: u32) {
        let (word, bit) = (v as usize / 64, v % 64);
        let mask = 1u64 << bit;
        if self.words[word] & mask == 0 {
            self.words[word] |= mask;
            self.len += 1;
        }
        self.cursor = self.cursor.min(word);
    }

    /// Takes the smallest slot.
    fn pop_min(&mut self) -> Option<u32> {
        if self.len == 0 {
            return None;
        }
        while self.words[self.cursor] == 0 {
            self.cursor += 1;
        }
        let word = self.words[self.cursor];
        self.words[self.cursor] = word & (word - 1);
        self.len -= 1;
        Some((self.cursor * 64) as u32 + word.trailing_zeros())
    }
}

/// When a count-driven decimation stops.
#[derive(Debug, Clone, Copy)]
pub(super) struct Target {
    pub(super) triangles: Option<usize>,
    pub(super) vertices: Option<usize>,
}

impl Target {
    /// Whether `mesh` is down to every count given (never without one), `removed` of its
    /// `initial_vertices` gone.
    fn reached(&self, mesh: &Mesh<'_>, initial_vertices: usize, removed: usize) -> bool {
        if self.triangles.is_none() && self.vertices.is_none() {
            return false;
        }
        self.triangles.is_none_or(|t| mesh.triangle_count() <= t)
            && self
                .vertices
                .is_none_or(|t| initial_vertices - removed <= t)
    }
}

/// A removal candidate: its cost, then the vertex, so ties go to the lower index (the
/// greedy order's heap entry, for grids and scattered points alike).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// The largest bound of the vertex's planned retriangulation.
    pub(crate) cost: f64,
    pub(crate) vertex: u32,
    /// The vertex's version when planned: stale once a neighbour's removal bumps it.
    pub(crate) version: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        // Reversed: BinaryHeap is a max-heap and we want the smallest cost first.
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.vertex.cmp(&self.vertex))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// Greedy order: always remove the vertex whose best retriangulation has the smallest
/// error. A key goes stale when a neighbour's removal changes the vertex's star; stale
/// keys are recognised by a per-vertex version and recomputed when popped.
pub(super) fn greedy(
    mesh: &mut Mesh<'_>,
    remover: &mut Remover<'_>,
    stats: &mut Stats,
    target: Target,
    initial_vertices: usize,
    progress: &mut dyn FnMut(Progress),
) {
    let n = mesh.vertex_slots();
    let mut version = vec![0u32; n];
    let mut heap = BinaryHeap::new();
    // After a count target's first sweeps, if any.
    stats.sweeps += 1;
    let sweep = stats.sweeps;
    progress(Progress {
        sweep,
        sweep_fraction: 0.0,
        removed: stats.removed,
    });
    for v in 0..n as u32 {
        if mesh.contains_vertex(v) {
            stats.attempts += 1;
            if let Some(cost) = remover.plan(mesh, v) {
                heap.push(Candidate {
                    cost,
                    vertex: v,
                    version: 0,
                });
            }
        }
    }
    // For the progress fraction: a count target's removals are known up front (each one
    // takes two triangles away); a bound's are not, so they count against all vertices.
    let expected_removals = match (target.vertices, target.triangles) {
        (Some(v), _) => initial_vertices.saturating_sub(v),
        (None, Some(t)) => mesh.triangle_count().saturating_sub(t) / 2,
        (None, None) => initial_vertices,
    }
    .max(1);
    let reached = |mesh: &Mesh<'_>, removed: usize| target.reached(mesh, initial_vertices, removed);
    while let Some(c) = heap.pop() {
        if reached(mesh, stats.removed) {
            break;
        }
        let v = c.vertex;
        if c.version != version[v as usize] || !mesh.contains_vertex(v) {
            continue;
        }
        stats.attempts += 1;
        let Some(cost) = remover.plan(mesh, v) else {
            continue;
        };
        debug_assert_eq!(cost.to_bits(), c.cost.to_bits(), "a current key is exact");
        remover.apply(mesh, v);
        stats.removed += 1;
        if stats.removed.is_multiple_of(65_536) {
            let sweep_fraction = (stats.removed as f64 / expected_removals as f64).min(1.0);
            progress(Progress {
                sweep,
                sweep_fraction,
                removed: stats.removed,
            });
        }
        for i in 0..remover.star.ring.len() {
            let u = remover.star.ring[i];
            version[u as usize] = version[u as usize].wrapping_add(1);
            stats.attempts += 1;
            if let Some(cost) = remover.plan(mesh, u) {
                heap.push(Candidate {
                    cost,
                    vertex: u,
                    version: version[u as usize],
                });
            }
        }
        // plan() for the neighbours replaced the star; restore nothing: apply() is done.
    }
}
