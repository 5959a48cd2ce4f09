//! A top-down initial mesh by greedy insertion (Garland & Heckbert, "Fast polygonal
//! approximation of terrains and height fields", 1995), with the exact error model (beyond
//! the paper).
//!
//! From the domain's corners, the sample of largest error is inserted into a Delaunay
//! triangulation, one at a time, until every triangle is within the limit. Each triangle
//! keeps its worst sample and its exact bound, found by one scan of the samples it covers
//! ([`triangle_worst`], [`crate::exact::triangle_error`]'s arithmetic); a priority queue
//! holds the triangles beyond the limit, largest error first. Only triangles an insertion
//! creates (split or flipped) are scanned again.
//!
//! Vertex removal from a start costs time per start vertex; where the result keeps a small
//! share of the samples, the RTIN and the strips keep many more than it, and removal walks
//! all the way down from there. Insertion stops near the result instead, and the removal
//! sweeps that follow take away what it over-placed.
//!
//! On a grid with variables, each triangle's bound and worst sample are the largest of
//! the height's and every variable's scaled ones (`crate::variables`), so a variable
//! beyond its own limit splits its triangle as the height does.
//!
//! # Scope
//! Grids without nodata only (the domain is the grid's rectangle, so the triangulation
//! of its convex hull is the domain's). For a tile whose border is decided
//! ([`crate::decimate_with_border`]), insertion starts from that border: the outline's
//! vertices are the kept border samples, and the triangles along it are measured over the
//! skipped ones like any other sample, so no border strip of half cells is needed. With a
//! maximum edge length, triangles with a longer edge (outside a decided outline) are split
//! too, at the sample nearest the middle of that edge.
//!
//! # Guarantees
//! Every emitted triangle is counter-clockwise, within the limit by its exact bound, and
//! the triangles tile the domain conformingly; the result depends only on the grid and
//! the arguments (ties in the queue go to the lower slot). `None` when the insertion
//! would pass `max_vertices` vertices (the caller's cue that another start is cheaper),
//! or on the rare grid where no sample is left to insert into a failing triangle.

use crate::exact::triangle_worst;
use crate::mesh::CompactBound;
use crate::predicates::{orient, Point};
use crate::{EdgeLimit, ErrorBound, Grid};

/// Insertion calls its `tick` once every this many vertices inserted.
const TICK_INSERTIONS: usize = 1024;

const NONE: u32 = u32::MAX;

/// Triangles (counter-clockwise sample indices) and their exact bounds of a greedy
/// insertion within `limit` over a grid without nodata (the caller checks), or `None`
/// (see the module docs). With `keep_border` (a tile
/// whose border is decided), the outline is exactly the grid's corners and the border
/// samples it keeps, inserted before anything is measured; the other border samples
/// never become vertices.
pub(crate) fn insertion_triangles(
    grid: &Grid,
    limit: f64,
    edge_limit: &EdgeLimit,
    keep_border: Option<&dyn Fn(u32, u32) -> bool>,
    max_vertices: usize,
    tick: &dyn Fn(),
) -> Option<(Vec<[u32; 3]>, Vec<CompactBound>)> {
    let (w, h) = (grid.width() as i64, grid.height() as i64);
    if w < 2 || h < 2 || limit <= 0.0 {
        return None;
    }
    debug_assert_eq!(grid.valid_cell_count() as i64, (w - 1) * (h - 1));
    let (x1, y1) = (w - 1, h - 1);
    let mut t = Triangulation::new(grid, limit, edge_limit, keep_border.is_some());
    let corners = [(0, 0), (x1, 0), (x1, y1), (0, y1)].map(|(x, y)| t.index(x, y));
    for &c in &corners {
        t.is_vertex[c as usize] = true;
    }
    t.vertices = 4;
    t.push([corners[0], corners[1], corners[2]], [NONE, NONE, 1]);
    t.push([corners[2], corners[3], corners[0]], [NONE, NONE, 0]);
    if let Some(keep) = keep_border {
        // The outline, counter-clockwise from the corner at (0, 0).
        let mut outline = Vec::new();
        outline.extend((1..x1).map(|x| (x, 0)));
        outline.extend((1..y1).map(|y| (x1, y)));
        outline.extend((1..x1).rev().map(|x| (x, y1)));
        outline.extend((1..y1).rev().map(|y| (0, y)));
        let mut hint = 0;
        for (x, y) in outline {
            let v = t.index(x, y);
            if keep(x as u32, y as u32) {
                hint = t.insert(hint, v)?;
                t.vertices += 1;
            } else {
                // Never a candidate: the border is decided.
                t.is_vertex[v as usize] = true;
            }
        }
    }
    t.dirty.clear();
    for s in 0..t.corners.len() as u32 {
        t.measure(s)?;
    }
    while let Some(slot) = t.queue.pop() {
        let sample = t.candidate[slot as usize]?;
        if t.is_vertex[sample] {
            // A long edge's middle sample, inserted meanwhile from the other side.
            t.measure(slot)?;
            continue;
        }
        if t.vertices >= max_vertices {
            return None;
        }
        if t.vertices.is_multiple_of(TICK_INSERTIONS) {
            tick();
        }
        t.insert(slot, sample as u32)?;
        t.vertices += 1;
        let mut dirty = std::mem::take(&mut t.dirty);
        dirty.sort_unstable();
        dirty.dedup();
        for s in dirty {
            t.measure(s)?;
        }
    }
    let bounds = t.bounds.into_iter().map(CompactBound::from).collect();
    Some((t.corners, bounds))
}

/// The triangles that must split, largest key first (their error; 0 when queued only
/// for a long edge), on a tie the lower slot: a binary heap indexed by slot, so that a
/// triangle measured again moves in it instead of leaving a stale entry behind (a heap of
/// stale entries cost 7 % of an insertion's profile on Fuji at ε = 5).
#[derive(Default)]
struct Queue {
    /// Slots in heap order.
    heap: Vec<u32>,
    /// Per slot: its index in `heap`, `NONE` when not queued.
    position: Vec<u32>,
    /// Per slot: its key while queued.
    key: Vec<u64>,
}

impl Queue {
    /// Whether slot `a` comes out before slot `b`.
    #[inline]
    fn before(&self, a: u32, b: u32) -> bool {
        let (ka, kb) = (self.key[a as usize], self.key[b as usize]);
        ka > kb || (ka == kb && a < b)
    }

    /// Queues `slot` with `key`, or moves it there if queued.
    fn set(&mut self, slot: u32, key: u64) {
        let s = slot as usize;
        if self.position.len() <= s {
            self.position.resize(s + 1, NONE);
            self.key.resize(s + 1, 0);
        }
        self.key[s] = key;
        let i = match self.position[s] {
            NONE => {
                self.heap.push(slot);
                self.heap.len() - 1
            }
            i => i as usize,
        };
        self.position[s] = i as u32;
        let i = self.sift_up(i);
        self.sift_down(i);
    }

    /// Takes `slot` out of the queue if it is in.
    fn remove(&mut self, slot: u32) {
        let Some(&i) = self.position.get(slot as usize) else {
            return;
        };
        if i == NONE {
            return;
        }
        self.position[slot as usize] = NONE;
        let last = self.heap.pop().expect("a queued slot is in the heap");
        if last != slot {
            let i = i as usize;
            self.heap[i] = last;
            self.position[last as usize] = i as u32;
            let i = self.sift_up(i);
            self.sift_down(i);
        }
    }

    /// The first slot, taken out of the queue.
    fn pop(&mut self) -> Option<u32> {
        let first = *self.heap.first()?;
        self.remove(first);
        Some(first)
    }

    fn sift_up(&mut self, mut i: usize) -> usize {
        while i > 0 {
            let parent = (i - 1) / 2;
            if !self.before(self.heap[i], self.heap[parent]) {
                break;
            }
            self.swap(i, parent);
            i = parent;
        }
        i
    }

    fn sift_down(&mut self, mut i: usize) {
        loop {
            let (l, r) = (2 * i + 1, 2 * i + 2);
            let mut first = i;
            if l < self.heap.len() && self.before(self.heap[l], self.heap[first]) {
                first = l;
            }
            if r < self.heap.len() && self.before(self.heap[r], self.heap[first]) {
                first = r;
            }
            if first == i {
                return;
            }
            self.swap(i, first);
            i = first;
        }
    }

    fn swap(&mut self, i: usize, j: usize) {
        self.heap.swap(i, j);
        self.position[self.heap[i] as usize] = i as u32;
        self.position[self.heap[j] as usize] = j as u32;
    }
}

/// A Delaunay triangulation of samples with each triangle's exact bound and worst sample.
struct Triangulation<'g> {
    grid: &'g Grid,
    limit: f64,
    edge_limit: &'g EdgeLimit,
    /// Whether the outline is decided (its edges are never split).
    fixed_outline: bool,
    width: i64,
    /// `width`, for the one `u32` division that finds a sample's row.
    width_u32: u32,
    /// Counter-clockwise corners (sample indices) per slot.
    corners: Vec<[u32; 3]>,
    /// The slot across edge `k` (corners `k`, `k + 1`), `NONE` on the outline.
    neighbours: Vec<[u32; 3]>,
    bounds: Vec<ErrorBound>,
    /// The sample to insert next into the slot's triangle, when it must split.
    candidate: Vec<Option<usize>>,
    is_vertex: Vec<bool>,
    vertices: usize,
    queue: Queue,
    /// Edges (slot, edge) waiting for Lawson's flips, kept to reuse its allocation.
    legalize: Vec<(u32, usize)>,
    /// Slots changed by the insertion under way, to measure once it is done.
    dirty: Vec<u32>,
}

impl<'g> Triangulation<'g> {
    fn new(
        grid: &'g Grid,
        limit: f64,
        edge_limit: &'g EdgeLimit,
        fixed_outline: bool,
    ) -> Triangulation<'g> {
        Triangulation {
            grid,
            limit,
            edge_limit,
            fixed_outline,
            width: i64::from(grid.width()),
            width_u32: grid.width(),
            corners: Vec::new(),
            neighbours: Vec::new(),
            bounds: Vec::new(),
            candidate: Vec::new(),
            is_vertex: vec![false; grid.values().len()],
            vertices: 0,
            queue: Queue::default(),
            legalize: Vec::new(),
            dirty: Vec::new(),
        }
    }

    fn index(&self, x: i64, y: i64) -> u32 {
        (y * self.width + x) as u32
    }

    #[inline]
    fn point(&self, v: u32) -> Point {
        let y = v / self.width_u32;
        let x = v - y * self.width_u32;
        Point {
            x: i64::from(x),
            y: i64::from(y),
            z: self
                .grid
                .vertex_height_at(v as usize, x as usize, y as usize),
        }
    }

    fn push(&mut self, corners: [u32; 3], neighbours: [u32; 3]) -> u32 {
        let slot = self.corners.len() as u32;
        self.corners.push(corners);
        self.neighbours.push(neighbours);
        self.bounds.push(ErrorBound::default());
        self.candidate.push(None);
        self.dirty.push(slot);
        slot
    }

    fn set(&mut self, slot: u32, corners: [u32; 3], neighbours: [u32; 3]) {
        let s = slot as usize;
        self.corners[s] = corners;
        self.neighbours[s] = neighbours;
        self.dirty.push(slot);
    }

    /// Points `slot`'s neighbour across the edge it shared with `old` at `new` instead.
    fn relink(&mut self, slot: u32, old: u32, new: u32) {
        if slot == NONE {
            return;
        }
        for n in &mut self.neighbours[slot as usize] {
            if *n == old {
                *n = new;
                return;
            }
        }
    }

    /// Measures a (changed) triangle and queues it if it must split; `None` when it must
    /// and no sample can split it (only decided border samples are beyond the limit).
    fn measure(&mut self, slot: u32) -> Option<()> {
        let s = slot as usize;
        let [a, b, c] = self.corners[s].map(|v| self.point(v));
        let mut measured = triangle_worst(self.grid, &a, &b, &c, &self.is_vertex);
        if self.grid.variable_count() > 0 {
            measured = crate::variables::worst_with_variables(
                self.grid,
                &a,
                &b,
                &c,
                &self.is_vertex,
                self.limit,
                measured,
            );
        }
        let (bound, worst) = measured;
        self.bounds[s] = bound;
        let error = bound.above.max(bound.below);
        let (key, candidate) = if error > self.limit {
            let (sample, e) = worst?;
            if e <= self.limit {
                return None;
            }
            (error.to_bits(), Some(sample))
        } else {
            let n = self.neighbours[s];
            // A triangle turned over on the globe splits its longest edge too.
            let turned_over = !self.edge_limit.faces_out(&a, &b, &c);
            let long = [(a, b, n[0]), (b, c, n[1]), (c, a, n[2])]
                .into_iter()
                .filter(|e| !(self.fixed_outline && e.2 == NONE))
                .map(|(p, q, _)| (self.edge_limit.measure(&p, &q), p, q))
                .max_by(|e, f| e.0.total_cmp(&f.0))
                .filter(|e| turned_over || !self.edge_limit.allows_measure(e.0));
            match long {
                None => {
                    self.candidate[s] = None;
                    self.queue.remove(slot);
                    return Some(());
                }
                Some((_, p, q)) => (0, self.middle_sample(&p, &q).or(worst.map(|w| w.0))),
            }
        };
        self.candidate[s] = candidate;
        self.queue.set(slot, key);
        Some(())
    }

    /// The sample nearest the middle of edge `pq` (rounded down), if not yet a vertex.
    fn middle_sample(&self, p: &Point, q: &Point) -> Option<usize> {
        let (x, y) = ((p.x + q.x).div_euclid(2), (p.y + q.y).div_euclid(2));
        let i = (y * self.width + x) as usize;
        (!self.is_vertex[i]).then_some(i)
    }

    /// Inserts sample `v` (not a vertex, inside the triangulation), walking from slot
    /// `hint` to the triangle holding it; returns a slot next to it.
    fn insert(&mut self, hint: u32, v: u32) -> Option<u32> {
        let p = self.point(v);
        let mut t = hint;
        let mut steps = 0usize;
        let (on_edge, t) = loop {
            let pts = self.corners[t as usize].map(|c| self.point(c));
            let o = [0, 1, 2].map(|k| orient(&pts[k], &pts[(k + 1) % 3], &p));
            if let Some(k) = (0..3).find(|&k| o[k] < 0) {
                t = self.neighbours[t as usize][k];
                steps += 1;
                if t == NONE || steps > self.corners.len() + 3 {
                    return None;
                }
                continue;
            }
            let zeros = o.iter().filter(|&&x| x == 0).count();
            if zeros > 1 {
                return None; // `p` is a corner
            }
            break ((0..3).find(|&k| o[k] == 0), t);
        };
        self.is_vertex[v as usize] = true;
        let mut legalize = std::mem::take(&mut self.legalize);
        legalize.clear();
        match on_edge {
            None => {
                let [a, b, c] = self.corners[t as usize];
                let [na, nb, nc] = self.neighbours[t as usize];
                let t1 = self.corners.len() as u32;
                let t2 = t1 + 1;
                self.set(t, [v, a, b], [t2, na, t1]);
                self.push([v, b, c], [t, nb, t2]);
                self.push([v, c, a], [t1, nc, t]);
                self.relink(nb, t, t1);
                self.relink(nc, t, t2);
                legalize.extend([(t, 1), (t1, 1), (t2, 1)]);
            }
            Some(k) => {
                let rot = |x: [u32; 3]| [x[k], x[(k + 1) % 3], x[(k + 2) % 3]];
                let [a, b, c] = rot(self.corners[t as usize]);
                let [u, n_bc, n_ca] = rot(self.neighbours[t as usize]);
                let t2 = self.corners.len() as u32;
                if u == NONE {
                    self.set(t, [v, c, a], [t2, n_ca, NONE]);
                    self.push([v, b, c], [NONE, n_bc, t]);
                    self.relink(n_bc, t, t2);
                    legalize.extend([(t, 1), (t2, 1)]);
                } else {
                    let uc = self.corners[u as usize];
                    let j = (0..3).find(|&j| uc[j] == b && uc[(j + 1) % 3] == a)?;
                    let d = uc[(j + 2) % 3];
                    let un = self.neighbours[u as usize];
                    let (n_ad, n_db) = (un[(j + 1) % 3], un[(j + 2) % 3]);
                    let u2 = t2 + 1;
                    // t: (v, c, a), t2: (v, b, c), u: (v, d, b), u2: (v, a, d).
                    self.set(t, [v, c, a], [t2, n_ca, u2]);
                    self.push([v, b, c], [u, n_bc, t]);
                    self.set(u, [v, d, b], [u2, n_db, t2]);
                    self.push([v, a, d], [t, n_ad, u]);
                    self.relink(n_bc, t, t2);
                    self.relink(n_ad, u, u2);
                    legalize.extend([(t, 1), (t2, 1), (u, 1), (u2, 1)]);
                }
            }
        }
        // Lawson's flips: an edge opposite `v` whose far vertex lies strictly inside the
        // circumcircle flips (cocircular ones stay, so the flips end).
        while let Some((t, e)) = legalize.pop() {
            let tc = self.corners[t as usize];
            debug_assert_eq!(tc[0], v);
            let u = self.neighbours[t as usize][e];
            if u == NONE {
                continue;
            }
            let (a, b) = (tc[e], tc[(e + 1) % 3]);
            let uc = self.corners[u as usize];
            let j = (0..3).find(|&j| uc[j] == b && uc[(j + 1) % 3] == a)?;
            let d = uc[(j + 2) % 3];
            let [pv, pa, pb, pd] = [v, a, b, d].map(|x| self.point(x));
            if in_circle(&pv, &pa, &pb, &pd) <= 0 {
                continue;
            }
            // t = (v, a, b) with e = 1, u = (b, a, d) -> t: (v, a, d), u: (v, d, b).
            let tn = self.neighbours[t as usize];
            let (n_va, n_bv) = (tn[0], tn[2]);
            let un = self.neighbours[u as usize];
            let (n_ad, n_db) = (un[(j + 1) % 3], un[(j + 2) % 3]);
            self.set(t, [v, a, d], [n_va, n_ad, u]);
            self.set(u, [v, d, b], [t, n_db, n_bv]);
            self.relink(n_ad, u, t);
            self.relink(n_bv, t, u);
            legalize.extend([(t, 1), (u, 1)]);
        }
        self.legalize = legalize;
        Some(t)
    }
}

/// Positive when `d` lies strictly inside the circle through counter-clockwise `abc`.
/// Exact: each term pairs an x-difference, a y-difference and a squared length, below
/// `2^32 * 2^63`.
fn in_circle(a: &Point, b: &Point, c: &Point, d: &Point) -> i128 {
    let diff = |p: &Point| {
        let (x, y) = (i128::from(p.x - d.x), i128::from(p.y - d.y));
        (x, y, x * x + y * y)
    };
    let (ax, ay, a2) = diff(a);
    let (bx, by, b2) = diff(b);
    let (cx, cy, c2) = diff(c);
    ax * (by * c2 - b2 * cy) - ay * (bx * c2 - b2 * cx) + a2 * (bx * cy - by * cx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edge_limit::NO_EDGE_LIMIT;
    use crate::mesh::Mesh;

    fn grid(w: u32, h: u32, f: impl Fn(i64, i64) -> f64) -> Grid {
        let values = (0..h as i64)
            .flat_map(|y| (0..w as i64).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Grid::new(w, h, values).unwrap()
    }

    fn bumpy(x: i64, y: i64) -> f64 {
        let (x, y) = (x as f64, y as f64);
        10.0 * (x * 0.3).sin() * (y * 0.2).cos() + 0.1 * ((x * 7.0 + y * 13.0) % 5.0)
    }

    /// Doubled areas of the triangles add up to the domain's, each within the limit.
    fn check(g: &Grid, limit: f64, corners: &[[u32; 3]], bounds: &[CompactBound]) {
        let w = i64::from(g.width());
        let p = |i: u32| Point {
            x: i64::from(i) % w,
            y: i64::from(i) / w,
            z: g.vertex_height(i as usize),
        };
        let mut area = 0;
        for (c, b) in corners.iter().zip(bounds) {
            let [a, b2, c2] = c.map(p);
            let o = orient(&a, &b2, &c2);
            assert!(o > 0);
            area += o;
            let exact =
                crate::exact::triangle_error(g, &a, &b2, &c2, limit).expect("within the limit");
            assert_eq!(CompactBound::from(exact), *b);
        }
        assert_eq!(area, 2 * (w - 1) * (i64::from(g.height()) - 1));
        // Conforming: linking succeeds.
        let _ = Mesh::from_triangles(g, corners.to_vec(), bounds.to_vec());
    }

    #[test]
    fn every_triangle_is_within_the_limit() {
        let g = grid(41, 29, bumpy);
        for limit in [0.05, 0.5, 2.0, 50.0] {
            let (c, b) = insertion_triangles(&g, limit, &NO_EDGE_LIMIT, None, usize::MAX, &|| {})
                .expect("no nodata");
            check(&g, limit, &c, &b);
        }
    }

    #[test]
    fn a_decided_border_is_the_outline() {
        let g = grid(41, 29, |x, y| if y == 0 { 0.0 } else { bumpy(x, y) });
        let keep = |x: u32, y: u32| y != 0 || x.is_multiple_of(10);
        let (c, b) =
            insertion_triangles(&g, 0.5, &NO_EDGE_LIMIT, Some(&keep), usize::MAX, &|| {}).unwrap();
        check(&g, 0.5, &c, &b);
        for t in &c {
            for &v in t {
                let (x, y) = (v % 41, v / 41);
                if x == 0 || y == 0 || x == 40 || y == 28 {
                    assert!(keep(x, y) || (x.is_multiple_of(40) && y.is_multiple_of(28)));
                }
            }
        }
    }

    #[test]
    fn long_edges_split() {
        let g = grid(33, 33, |x, y| (x + y) as f64);
        let three =
            EdgeLimit::new(&crate::EdgeMetric::Grid, Some(3), g.width(), g.height()).unwrap();
        let (c, b) = insertion_triangles(&g, 1.0, &three, None, usize::MAX, &|| {}).unwrap();
        check(&g, 1.0, &c, &b);
        let w = 33;
        for t in &c {
            for k in 0..3 {
                let (p, q) = (i64::from(t[k]), i64::from(t[(k + 1) % 3]));
                let (dx, dy) = (p % w - q % w, p / w - q / w);
                assert!(dx * dx + dy * dy <= 9);
            }
        }
    }

    #[test]
    fn a_plane_is_two_triangles_and_a_budget_stops_it() {
        let g = grid(20, 20, |x, y| 2.0 * x as f64 - y as f64);
        let (c, _) =
            insertion_triangles(&g, 0.1, &NO_EDGE_LIMIT, None, usize::MAX, &|| {}).unwrap();
        assert_eq!(c.len(), 2);
        let rough = grid(20, 20, bumpy);
        assert!(insertion_triangles(&rough, 0.01, &NO_EDGE_LIMIT, None, 10, &|| {}).is_none());
    }
}
