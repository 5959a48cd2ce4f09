//! Contouring a mesh: segments per triangle, joined through shared edges into polylines.

use crate::crossing::{crossing_point, segment};
use crate::mesh::NONE;
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
/// `O(triangles × log(levels) + segments)` after the mesh is built.
pub fn contour(mesh: &ContourMesh, levels: &[f64]) -> Result<Vec<Polyline>> {
    let levels = sorted_levels(levels)?;
    let vertices = mesh.vertices();
    let triangles = mesh.triangles();
    // Which triangles each level cuts: those with min z < level <= max z.
    let mut cut: Vec<Vec<u32>> = vec![Vec::new(); levels.len()];
    for (t, tri) in triangles.iter().enumerate() {
        let z = tri.map(|v| vertices[v as usize][2]);
        let (lo, hi) = (z[0].min(z[1]).min(z[2]), z[0].max(z[1]).max(z[2]));
        let first = levels.partition_point(|&l| l <= lo);
        let end = levels.partition_point(|&l| l <= hi);
        for bucket in &mut cut[first..end] {
            bucket.push(t as u32);
        }
    }
    let mut joiner = Joiner {
        mesh,
        slot: vec![NONE; triangles.len()],
        used: Vec::new(),
        walk: Vec::new(),
    };
    let mut lines = Vec::new();
    for (level, bucket) in levels.iter().zip(&cut) {
        let start = lines.len();
        joiner.join(*level, bucket, &mut lines)?;
        lines[start..].sort_by_key(|l: &Polyline| l.edges[0]);
    }
    Ok(lines)
}

/// Joins one level's segments; holds the buffers reused across levels.
struct Joiner<'a> {
    mesh: &'a ContourMesh,
    /// Triangle -> its index in the current level's bucket, or `NONE`.
    slot: Vec<u32>,
    /// Per bucket entry: its segment already belongs to a line.
    used: Vec<bool>,
    /// Half-edges crossed by the line being walked.
    walk: Vec<u32>,
}

impl Joiner<'_> {
    fn join(&mut self, level: f64, bucket: &[u32], lines: &mut Vec<Polyline>) -> Result<()> {
        for (i, &t) in bucket.iter().enumerate() {
            self.slot[t as usize] = i as u32;
        }
        self.used.clear();
        self.used.resize(bucket.len(), false);
        let result = self.join_slotted(level, bucket, lines);
        for &t in bucket {
            self.slot[t as usize] = NONE;
        }
        result
    }

    fn join_slotted(
        &mut self,
        level: f64,
        bucket: &[u32],
        lines: &mut Vec<Polyline>,
    ) -> Result<()> {
        // Open lines first, from each not yet used segment on a boundary edge...
        for (i, &t) in bucket.iter().enumerate() {
            if self.used[i] {
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
            self.emit(level, false, lines);
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
            self.emit(level, true, lines);
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

    /// Turns `self.walk` into a [`Polyline`]: high ground on the left, a ring started at
    /// its smallest edge, coincident points merged; dropped if it collapses to a point.
    fn emit(&mut self, level: f64, closed: bool, lines: &mut Vec<Polyline>) {
        let tris = self.mesh.triangles();
        let verts = self.mesh.vertices();
        let edge = |h: u32| {
            let tri = tris[(h / 3) as usize];
            let (p, q) = (tri[(h % 3) as usize], tri[((h + 1) % 3) as usize]);
            [p.min(q), p.max(q)]
        };
        // Direction: the first segment must run entry -> exit.
        let (first_t, first_in) = (self.walk[0] / 3, self.walk[0] % 3);
        let (entry, _) = self.segment(first_t, level);
        if entry != first_in {
            self.walk.reverse();
        }
        if closed {
            // Drop the repeated start, rotate to the smallest edge, close again.
            self.walk.pop();
            let m = (0..self.walk.len())
                .min_by_key(|&i| edge(self.walk[i]))
                .unwrap_or(0);
            self.walk.rotate_left(m);
            self.walk.push(self.walk[0]);
        }
        let n = self.walk.len();
        let mut points: Vec<[f64; 2]> = Vec::with_capacity(n);
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(n);
        for (i, &h) in self.walk.iter().enumerate() {
            let [p, q] = edge(h);
            let point = crossing_point(verts[p as usize], verts[q as usize], level);
            if points.last() == Some(&point) {
                // Coincident crossings (at a vertex on the level) become one point; the
                // line's last point keeps its own edge, so an open line still ends on its
                // boundary edge and a ring on its first edge.
                if i == n - 1 {
                    *edges.last_mut().expect("not empty") = [p, q];
                }
                continue;
            }
            points.push(point);
            edges.push([p, q]);
        }
        remove_spikes(&mut points, &mut edges);
        let degenerate = if closed {
            // A ring needs three distinct points (its first is repeated at the end): `A,
            // B, A` encloses nothing.
            points.len() < 4
        } else {
            points.len() < 2
        };
        if !degenerate {
            lines.push(Polyline {
                level,
                points,
                edges,
                closed,
            });
        }
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
