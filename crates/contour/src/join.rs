//! Contouring a mesh: segments per triangle, joined through shared edges into polylines.

use crate::crossing::{crossing_point, segment};
use crate::mesh::NONE;
use crate::regularize::without_zero_width_parts;
use crate::{levels::sorted_levels, ContourMesh, Error, Polyline, Result};

/// The contour lines of `mesh` at each of `levels`, by marching triangles.
///
/// For each level, every triangle the level cuts (see the perturbation rule in the crate
/// docs: a height equal to the level counts as above it) gives one segment between two of
/// its edges. Segments are joined through the edges they share with the neighbouring
/// triangle (edges are identified by their two vertex indices, never by coordinates), so
/// every line is a path, not a soup: it is closed when it comes back to its first edge, and
/// otherwise it runs from a boundary edge to a boundary edge (the domain's outline or a
/// nodata hole). Crossings that coincide at a vertex lying exactly on the level are merged
/// into one point; a line running out along an edge at the level and back (`A, B, A`)
/// loses the excursion; and a line that collapses to a point or a ring that encloses
/// nothing (ground that only touches the level at a vertex or along edges) is dropped.
/// Edges at the level walked once each way by different lines (a ridge at the level
/// between a ring and a line, or reaching the boundary) are dropped from both, which are
/// joined where the ridge left them: no segment is written twice.
///
/// # Output order (deterministic)
/// Sorted by level (ascending; `levels` may be in any order, duplicates are contoured
/// once), then by the edge of the line's first point, as `(smaller vertex, larger vertex)`.
/// A closed line starts at its smallest edge; an open line starts at the end that puts the
/// high ground on its left (see [`Polyline`]). The result depends only on the mesh and the
/// levels.
///
/// # Errors
/// [`Error::InvalidLevel`] for a NaN or infinite level. [`Error::Internal`] if the
/// joining meets a state a valid [`ContourMesh`] cannot produce (a bug guard, instead of a
/// loop or a panic).
///
/// # Runtime
/// `O(vertices × log(levels) + triangles + segments)` after the mesh is built.
pub fn contour(mesh: &ContourMesh, levels: &[f64]) -> Result<Vec<Polyline>> {
    let levels = sorted_levels(levels)?;
    let mut lines = Vec::new();
    walk_levels(mesh, &levels, None, |_, level, walk| {
        lines.extend(finish_line(level, walk.closed, walk.crossings));
        Ok(())
    })?;
    let mut lines = without_zero_width_parts(lines);
    sort_lines(&mut lines);
    Ok(lines)
}

/// Sorts lines by level, then by the edge under their first point: the output order of
/// [`contour`] (levels are distinct, and no two lines of a level start on the same edge).
pub(crate) fn sort_lines(lines: &mut [Polyline]) {
    lines.sort_by(|a, b| {
        a.level
            .total_cmp(&b.level)
            .then(a.edges[0].cmp(&b.edges[0]))
    });
}

/// One crossing of a line with a mesh edge: the edge (as `[smaller id, larger id]`) and the
/// crossing point on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Crossing {
    pub(crate) edge: [u32; 2],
    pub(crate) point: [f64; 2],
}

/// A walk of one line through a mesh, entry to exit (high ground on the left): the edges it
/// crosses in order, first and last included.
pub(crate) struct Walk {
    pub(crate) crossings: Vec<Crossing>,
    /// A ring (its last crossing repeats its first), not a walk from a boundary edge to a
    /// boundary edge.
    pub(crate) closed: bool,
}

/// Walks every line of `mesh` at each of `levels` (sorted, distinct) and hands each to
/// `found` with its level's index and value: for each level, the walks from boundary edges
/// first (in the order of their triangles), then the rings. Edges are named through `ids`
/// (vertex index -> id) when given, else by vertex index.
pub(crate) fn walk_levels(
    mesh: &ContourMesh,
    levels: &[f64],
    ids: Option<&[u32]>,
    mut found: impl FnMut(usize, f64, Walk) -> Result<()>,
) -> Result<()> {
    let vertices = mesh.vertices();
    let triangles = mesh.triangles();
    // Which triangles each level cuts: those with min z < level <= max z, i.e. the levels
    // at or below the highest corner but not at or below the lowest (counted per vertex:
    // the count is monotone in the height).
    let at_or_below: Vec<u32> = vertices
        .iter()
        .map(|v| levels.partition_point(|&l| l <= v[2]) as u32)
        .collect();
    let mut cut: Vec<Vec<u32>> = vec![Vec::new(); levels.len()];
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| at_or_below[v as usize]);
        let (first, end) = (a.min(b).min(c) as usize, a.max(b).max(c) as usize);
        for bucket in &mut cut[first..end] {
            bucket.push(t as u32);
        }
    }
    let mut joiner = Joiner {
        mesh,
        ids,
        slot: vec![NONE; triangles.len()],
        used: Vec::new(),
        walk: Vec::new(),
    };
    for (index, (&level, bucket)) in levels.iter().zip(&cut).enumerate() {
        joiner.join(level, bucket, &mut |level, walk| found(index, level, walk))?;
    }
    Ok(())
}

/// Joins one level's segments; holds the buffers reused across levels.
struct Joiner<'a> {
    mesh: &'a ContourMesh,
    /// Vertex index -> the id edges are named by, when not the index itself.
    ids: Option<&'a [u32]>,
    /// Triangle -> its index in the current level's bucket, or `NONE`.
    slot: Vec<u32>,
    /// Per bucket entry: its segment already belongs to a line.
    used: Vec<bool>,
    /// Half-edges crossed by the line being walked.
    walk: Vec<u32>,
}

impl Joiner<'_> {
    fn join(
        &mut self,
        level: f64,
        bucket: &[u32],
        found: &mut dyn FnMut(f64, Walk) -> Result<()>,
    ) -> Result<()> {
        for (i, &t) in bucket.iter().enumerate() {
            self.slot[t as usize] = i as u32;
        }
        self.used.clear();
        self.used.resize(bucket.len(), false);
        let result = self.join_slotted(level, bucket, found);
        for &t in bucket {
            self.slot[t as usize] = NONE;
        }
        result
    }

    fn join_slotted(
        &mut self,
        level: f64,
        bucket: &[u32],
        found: &mut dyn FnMut(f64, Walk) -> Result<()>,
    ) -> Result<()> {
        // Open lines first, from each not yet used segment on a boundary edge...
        for (i, &t) in bucket.iter().enumerate() {
            let on_boundary = (0..3).any(|k| self.mesh.twin(3 * t + k) == NONE);
            if self.used[i] || !on_boundary {
                continue;
            }
            let (entry, exit) = self.segment(t, level);
            let start = if self.mesh.twin(3 * t + entry) == NONE {
                entry
            } else if self.mesh.twin(3 * t + exit) == NONE {
                exit
            } else {
                continue;
            };
            let closed = self.walk_from(level, bucket.len(), t, start)?;
            if closed {
                return Err(Error::Internal {
                    level,
                    what: "a line from a boundary edge came back to its start",
                });
            }
            let walk = self.crossings(level, false);
            found(level, walk)?;
        }
        // ...then the rings that remain.
        for (i, &t) in bucket.iter().enumerate() {
            if self.used[i] {
                continue;
            }
            let (entry, _) = self.segment(t, level);
            if !self.walk_from(level, bucket.len(), t, entry)? {
                return Err(Error::Internal {
                    level,
                    what: "a line from an interior edge reached the boundary",
                });
            }
            let walk = self.crossings(level, true);
            found(level, walk)?;
        }
        Ok(())
    }

    /// The segment of triangle `t` at `level`, as local edges `(entry, exit)`.
    fn segment(&self, t: u32, level: f64) -> (u32, u32) {
        let tri = self.mesh.triangles()[t as usize];
        let c = tri.map(|v| self.mesh.vertices()[v as usize]);
        let (entry, exit) = segment(c, level).expect("every bucketed triangle is cut");
        (entry as u32, exit as u32)
    }

    /// Walks from triangle `t`, entering through its local edge `enter`, until the line
    /// leaves the mesh (returns `false`) or comes back to `t` (returns `true`); the crossed
    /// half-edges are left in `self.walk`, first and last included.
    fn walk_from(&mut self, level: f64, limit: usize, t: u32, enter: u32) -> Result<bool> {
        self.walk.clear();
        self.walk.push(3 * t + enter);
        let (mut cur, mut cur_in) = (t, enter);
        for _ in 0..=limit {
            self.used[self.slot[cur as usize] as usize] = true;
            let (a, b) = self.segment(cur, level);
            let out = if a == cur_in { b } else { a };
            self.walk.push(3 * cur + out);
            let twin = self.mesh.twin(3 * cur + out);
            if twin == NONE {
                return Ok(false);
            }
            let next = twin / 3;
            if next == t {
                return Ok(true);
            }
            let s = self.slot[next as usize];
            if s == NONE || self.used[s as usize] {
                return Err(Error::Internal {
                    level,
                    what: "a crossed edge leads to a triangle without a free segment",
                });
            }
            cur = next;
            cur_in = twin % 3;
        }
        Err(Error::Internal {
            level,
            what: "a line is longer than the number of segments",
        })
    }

    /// The crossings of `self.walk`, turned to run entry -> exit (high ground on the left).
    fn crossings(&mut self, level: f64, closed: bool) -> Walk {
        let tris = self.mesh.triangles();
        let verts = self.mesh.vertices();
        // Direction: the first segment must run entry -> exit.
        let (first_t, first_in) = (self.walk[0] / 3, self.walk[0] % 3);
        let (entry, _) = self.segment(first_t, level);
        if entry != first_in {
            self.walk.reverse();
        }
        let id = |v: u32| self.ids.map_or(v, |ids| ids[v as usize]);
        let crossings = self
            .walk
            .iter()
            .map(|&h| {
                let tri = tris[(h / 3) as usize];
                let (p, q) = (tri[(h % 3) as usize], tri[((h + 1) % 3) as usize]);
                let (ip, iq) = (id(p), id(q));
                Crossing {
                    edge: [ip.min(iq), ip.max(iq)],
                    point: crossing_point(verts[p as usize], verts[q as usize], level),
                }
            })
            .collect();
        Walk { crossings, closed }
    }
}

/// Turns a walk's crossings into a [`Polyline`]: a ring started at its smallest edge,
/// coincident points merged, excursions removed; `None` if it collapses to a point (or a
/// ring to fewer than three distinct points). A ring's last crossing repeats its first.
pub(crate) fn finish_line(
    level: f64,
    closed: bool,
    mut crossings: Vec<Crossing>,
) -> Option<Polyline> {
    if closed {
        // Drop the repeated start, rotate to the smallest edge, close again.
        crossings.pop();
        let m = (0..crossings.len())
            .min_by_key(|&i| crossings[i].edge)
            .unwrap_or(0);
        crossings.rotate_left(m);
        crossings.push(crossings[0]);
    }
    let n = crossings.len();
    let mut points: Vec<[f64; 2]> = Vec::with_capacity(n);
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(n);
    for (i, c) in crossings.iter().enumerate() {
        if points.last() == Some(&c.point) {
            // Coincident crossings (at a vertex on the level) become one point; the
            // line's last point keeps its own edge, so an open line still ends on its
            // boundary edge and a ring on its first edge.
            if i == n - 1 {
                *edges.last_mut().expect("not empty") = c.edge;
            }
            continue;
        }
        points.push(c.point);
        edges.push(c.edge);
    }
    remove_spikes(&mut points, &mut edges);
    if closed {
        remove_spikes_across_the_start(&mut points, &mut edges);
    }
    let degenerate = if closed {
        // A ring needs three distinct points (its first is repeated at the end): `A,
        // B, A` encloses nothing.
        points.len() < 4
    } else {
        points.len() < 2
    };
    (!degenerate).then_some(Polyline {
        level,
        points,
        edges,
        closed,
    })
}

/// Removes a ring's excursions across its start, which [`remove_spikes`] keeps (it keeps
/// the first and last points): read cyclically, a ring `B, A, .., A, B` has its tip `B` at
/// the start, and `A, .., A, B, A` at the end. Where one goes, the ring starts again at its
/// smallest edge, so what is removed does not depend on where the walk began (on how the
/// mesh numbers its vertices).
fn remove_spikes_across_the_start(points: &mut Vec<[f64; 2]>, edges: &mut Vec<[u32; 2]>) {
    if points.len() < 4 {
        return;
    }
    // The ring without its closing point.
    points.pop();
    edges.pop();
    let mut changed = false;
    while points.len() >= 3 {
        let m = points.len();
        if points[1] == points[m - 1] {
            // The tip is the first point: it goes with the last (the same point as the
            // second).
            points.remove(0);
            edges.remove(0);
            points.pop();
            edges.pop();
        } else if points[m - 2] == points[0] {
            // The tip is the last point: it goes with the one before (the same point as
            // the first).
            points.truncate(m - 2);
            edges.truncate(m - 2);
        } else {
            break;
        }
        changed = true;
    }
    if changed && !points.is_empty() {
        let m = (0..points.len()).min_by_key(|&i| edges[i]).unwrap_or(0);
        points.rotate_left(m);
        edges.rotate_left(m);
    }
    if let (Some(&p), Some(&e)) = (points.first(), edges.first()) {
        points.push(p);
        edges.push(e);
    }
}

/// Removes the back-and-forth excursions `A, B, A` inside a line (keeping the first `A`),
/// repeatedly, so `A, B, C, B, A` goes too. They come from ground that only touches the
/// level along an edge (a ridge at the level between lower ground): the rule that a height
/// at the level counts as above makes the line run out along the edge and back. The first
/// and last points stay, so open lines still end on their boundary edges and rings close.
fn remove_spikes(points: &mut Vec<[f64; 2]>, edges: &mut Vec<[u32; 2]>) {
    let n = points.len();
    if n < 4 {
        return;
    }
    let mut kept = 1;
    for i in 1..n {
        points[kept] = points[i];
        edges[kept] = edges[i];
        kept += 1;
        // A spike tip at `kept - 2`, not touching the first or the last point.
        while kept >= 3 && i < n - 1 && points[kept - 3] == points[kept - 1] {
            kept -= 2;
        }
    }
    points.truncate(kept);
    edges.truncate(kept);
}
