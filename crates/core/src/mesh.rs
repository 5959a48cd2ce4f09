//! The working triangle mesh over a grid: triangles with neighbour links, per-triangle
//! error bounds, and vertex stars (paper §3.2).
//!
//! Vertices are grid sample indices (`y * width + x`). Triangle `t` stores its corners
//! counter-clockwise and, for each edge `i` (from corner `i` to corner `i + 1`), the
//! triangle across it or [`NONE`] on the domain boundary. Removing a vertex reuses its star
//! triangles' slots, so the triangle array never grows.

use crate::predicates::{orient, Point};
use crate::{ErrorBound, Grid};

/// Marks a missing triangle, neighbour or vertex link.
pub(crate) const NONE: u32 = u32::MAX;

/// The paper's vertex classes (§3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexClass {
    /// A complete cycle of triangles around the vertex.
    Interior,
    /// A half cycle of triangles whose two boundary edges are collinear (a 180° angle).
    Boundary,
    /// Any other vertex on the domain boundary, including vertices where the domain
    /// pinches (two separate fans of triangles). Never removed: it shapes the domain.
    Corner,
}

/// An [`ErrorBound`] in `f32`, each side rounded up so it still bounds the error.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct CompactBound {
    above: f32,
    below: f32,
}

impl From<ErrorBound> for CompactBound {
    fn from(b: ErrorBound) -> CompactBound {
        CompactBound {
            above: round_up(b.above),
            below: round_up(b.below),
        }
    }
}

impl From<CompactBound> for ErrorBound {
    fn from(b: CompactBound) -> ErrorBound {
        ErrorBound {
            above: b.above as f64,
            below: b.below as f64,
        }
    }
}

/// The smallest `f32` at or above `x`.
fn round_up(x: f64) -> f32 {
    let r = x as f32;
    if (r as f64) < x {
        r.next_up()
    } else {
        r
    }
}

/// The star of a vertex: its neighbours counter-clockwise and the triangles between them.
#[derive(Debug, Default)]
pub(crate) struct Star {
    /// Neighbour vertices, counter-clockwise. For a boundary star the first and last are
    /// the ends of the two boundary edges.
    pub ring: Vec<u32>,
    /// `triangles[i]` has corners `(centre, ring[i], ring[i + 1 mod len])`.
    pub triangles: Vec<u32>,
    /// `outer[i]`: the triangle across ring edge `ring[i] -> ring[i + 1 mod len]` from
    /// `triangles[i]`, outside the star, or [`NONE`] on the domain boundary.
    pub outer: Vec<u32>,
    /// Whether the star is a half cycle (the vertex is on the domain boundary).
    pub open: bool,
}

/// Where a mesh's vertices are and what heights they carry: a grid's samples (vertex ids
/// are sample indices) or scattered points (vertex ids are point indices).
pub(crate) trait Vertices {
    /// Position and height of vertex `v` (for a grid, [`Grid::vertex_height`]).
    fn point(&self, v: u32) -> Point;
    /// Position and sample value at vertex `v`.
    fn sample_point(&self, v: u32) -> Point;
    /// Number of vertex ids.
    fn vertex_count(&self) -> usize;
}

impl Vertices for Grid {
    #[inline]
    fn point(&self, v: u32) -> Point {
        let w = self.width() as usize;
        let i = v as usize;
        let (x, y) = (i % w, i / w);
        Point {
            x: x as i64,
            y: y as i64,
            z: self.vertex_height_at(i, x, y),
        }
    }

    #[inline]
    fn sample_point(&self, v: u32) -> Point {
        let w = self.width() as usize;
        let i = v as usize;
        Point {
            x: (i % w) as i64,
            y: (i / w) as i64,
            z: self.values()[i],
        }
    }

    fn vertex_count(&self) -> usize {
        self.width() as usize * self.height() as usize
    }
}

/// Triangle mesh over a grid's domain or over scattered points, with per-triangle
/// [`ErrorBound`]s. Generic over where its vertices are, so that stars, classes and
/// removals are shared; monomorphized, so the grid's mesh pays nothing for it.
#[derive(Debug)]
pub(crate) struct Mesh<'g, V: Vertices + ?Sized = Grid> {
    samples: &'g V,
    corners: Vec<[u32; 3]>,
    neighbours: Vec<[u32; 3]>,
    /// Bounds stored as `f32` rounded up (so still bounds), halving their memory.
    bounds: Vec<CompactBound>,
    /// One live triangle incident to each vertex, or `NONE` if the vertex is not in the mesh.
    vertex_triangle: Vec<u32>,
    /// Vertices where the domain pinches: never removable.
    pinched: Vec<bool>,
    live_triangles: usize,
}

impl<'g> Mesh<'g, Grid> {
    /// The initial mesh (paper §4): each valid cell split into two triangles along its
    /// `(x, y)`-`(x + 1, y + 1)` diagonal, all bounds zero.
    pub(crate) fn from_grid(grid: &'g Grid) -> Mesh<'g> {
        let (w, h) = (grid.width() as usize, grid.height() as usize);
        let cells_w = w.saturating_sub(1);
        let cells = cells_w * h.saturating_sub(1);
        let mut corners = vec![[NONE; 3]; 2 * cells];
        let mut neighbours = vec![[NONE; 3]; 2 * cells];
        let mut vertex_triangle = vec![NONE; w * h];
        let mut live = 0;
        let valid = |cx: usize, cy: usize| cx < cells_w && cy < h - 1 && grid.cell_is_valid(cx, cy);
        for cy in 0..h.saturating_sub(1) {
            for cx in 0..cells_w {
                if !valid(cx, cy) {
                    continue;
                }
                let c = cy * cells_w + cx;
                let a = (cy * w + cx) as u32;
                let (b, cc, d) = (a + 1, a + 1 + w as u32, a + w as u32);
                let (lower, upper) = (2 * c, 2 * c + 1);
                // lower = (a, b, cc): edges a->b (row above), b->cc (cell to the right),
                // cc->a (diagonal). upper = (a, cc, d): a->cc (diagonal), cc->d (row
                // below), d->a (cell to the left).
                corners[lower] = [a, b, cc];
                corners[upper] = [a, cc, d];
                neighbours[lower] = [
                    if cy > 0 && valid(cx, cy - 1) {
                        (2 * (c - cells_w) + 1) as u32
                    } else {
                        NONE
                    },
                    if valid(cx + 1, cy) {
                        (2 * (c + 1) + 1) as u32
                    } else {
                        NONE
                    },
                    upper as u32,
                ];
                neighbours[upper] = [
                    lower as u32,
                    if valid(cx, cy + 1) {
                        (2 * (c + cells_w)) as u32
                    } else {
                        NONE
                    },
                    if cx > 0 && valid(cx - 1, cy) {
                        (2 * (c - 1)) as u32
                    } else {
                        NONE
                    },
                ];
                for v in [a, b, cc] {
                    vertex_triangle[v as usize] = lower as u32;
                }
                for v in [a, cc, d] {
                    vertex_triangle[v as usize] = upper as u32;
                }
                live += 2;
            }
        }
        let mut mesh = Mesh {
            samples: grid,
            corners,
            bounds: vec![CompactBound::default(); 2 * cells],
            neighbours,
            vertex_triangle,
            pinched: vec![false; w * h],
            live_triangles: live,
        };
        mesh.mark_pinched();
        mesh
    }

    /// A mesh from counter-clockwise triangles over grid samples (vertex ids are sample
    /// indices) that tile part of the grid's domain conformingly, with their bounds.
    /// Neighbours are found by matching edges (by their midpoints).
    pub(crate) fn from_triangles(
        grid: &'g Grid,
        corners: Vec<[u32; 3]>,
        bounds: Vec<CompactBound>,
    ) -> Mesh<'g> {
        let (w, h) = (grid.width() as usize, grid.height() as usize);
        let n = w * h;
        let mut vertex_triangle = vec![NONE; n];
        // In a conforming triangulation no two edges share a midpoint, so the midpoint
        // (on the doubled lattice) names the edge: the first triangle to reach it waits
        // there for its twin. 16 bytes per sample, less than per-vertex triangle lists.
        let doubled_width = 2 * w - 1;
        let mut waiting = vec![NONE; doubled_width * (2 * h - 1)];
        let mut neighbours = vec![[NONE; 3]; corners.len()];
        for (t, c) in corners.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (c[e] as usize, c[(e + 1) % 3] as usize);
                vertex_triangle[a] = t as u32;
                let key = (a % w + b % w) + (a / w + b / w) * doubled_width;
                let u = waiting[key];
                if u == NONE {
                    waiting[key] = t as u32;
                    continue;
                }
                let cu = corners[u as usize];
                let k = (0..3)
                    .find(|&k| cu[k] as usize == b && cu[(k + 1) % 3] as usize == a)
                    .expect("the triangles are conforming");
                neighbours[t][e] = u;
                neighbours[u as usize][k] = t as u32;
            }
        }
        drop(waiting);
        let live = corners.len();
        let mut mesh = Mesh {
            samples: grid,
            corners,
            bounds,
            neighbours,
            vertex_triangle,
            pinched: vec![false; n],
            live_triangles: live,
        };
        mesh.mark_pinched();
        mesh
    }

    /// If `v` is the corner of exactly one triangle, and that triangle's edge opposite `v`
    /// is shared with a triangle that, with it, forms a convex quadrilateral, flips that
    /// edge so that it runs through `v`; returns whether it flipped. The new triangles get
    /// their exact errors as bounds.
    pub(crate) fn flip_into_corner(&mut self, v: u32) -> bool {
        let t = self.vertex_triangle[v as usize];
        if t == NONE {
            return false;
        }
        let i = self.local(t, v);
        if self.neighbours[t as usize][i] != NONE
            || self.neighbours[t as usize][(i + 2) % 3] != NONE
        {
            return false; // v has more than one triangle
        }
        // t = (a, b, v): the edge a -> b is opposite v; u = (b, a, d) across it.
        let e = (i + 1) % 3;
        let Some((_, quad)) = self.quad(t, e) else {
            return false;
        };
        let [pa, pb, pc, pd] = quad.map(|w| self.point(w));
        if orient(&pc, &pa, &pd) <= 0 || orient(&pc, &pd, &pb) <= 0 {
            return false;
        }
        let exact = |p: &Point, q: &Point, r: &Point| {
            crate::exact::triangle_error(self.samples, p, q, r, f64::INFINITY).expect("no limit")
        };
        let bounds = [exact(&pc, &pa, &pd), exact(&pc, &pd, &pb)];
        self.flip(t, e, bounds);
        true
    }
}

impl<'g, V: Vertices + ?Sized> Mesh<'g, V> {
    /// The triangle across edge `j` of `t` (from corner `j` to corner `j + 1`), or
    /// [`NONE`] on the domain boundary.
    pub(crate) fn across(&self, t: u32, j: usize) -> u32 {
        self.neighbours[t as usize][j]
    }

    /// Corners of live triangle `t`, counter-clockwise.
    pub(crate) fn corners(&self, t: u32) -> [u32; 3] {
        self.corners[t as usize]
    }

    /// Number of triangle slots (live or dead).
    pub(crate) fn triangle_slots(&self) -> usize {
        self.corners.len()
    }

    /// The quadrilateral around edge `j` of live triangle `t`: the triangle `u` across it
    /// and the corners `[a, b, c, d]`, where `t = (a, b, c)` and `u = (b, a, d)`; `None`
    /// on the domain boundary.
    pub(crate) fn quad(&self, t: u32, j: usize) -> Option<(u32, [u32; 4])> {
        let u = self.neighbours[t as usize][j];
        if u == NONE {
            return None;
        }
        let corners = self.corners[t as usize];
        let [a, b, c] = [0, 1, 2].map(|k| corners[(j + k) % 3]);
        let k = self.edge_index(u, b, a);
        let d = self.corners[u as usize][(k + 2) % 3];
        Some((u, [a, b, c, d]))
    }

    /// Flips edge `j` of live triangle `t` (from `a`, corner `j`, to `b`; `c` opposite),
    /// shared with `u = (b, a, d)`, into the edge `c d`: `t` becomes `(c, a, d)` and `u`
    /// becomes `(c, d, b)`, with the given bounds. The caller has checked that the
    /// quadrilateral `c a d b` is strictly convex, so both stay counter-clockwise.
    pub(crate) fn flip(&mut self, t: u32, j: usize, bounds: [ErrorBound; 2]) {
        let [a, b, c] = [0, 1, 2].map(|k| self.corners[t as usize][(j + k) % 3]);
        let u = self.neighbours[t as usize][j];
        let k = self.edge_index(u, b, a);
        let d = self.corners[u as usize][(k + 2) % 3];
        let t_bc = self.neighbours[t as usize][(j + 1) % 3];
        let t_ca = self.neighbours[t as usize][(j + 2) % 3];
        let u_ad = self.neighbours[u as usize][(k + 1) % 3];
        let u_db = self.neighbours[u as usize][(k + 2) % 3];
        self.corners[t as usize] = [c, a, d];
        self.neighbours[t as usize] = [t_ca, u_ad, u];
        self.corners[u as usize] = [c, d, b];
        self.neighbours[u as usize] = [t, u_db, t_bc];
        if u_ad != NONE {
            let e = self.edge_index(u_ad, d, a);
            self.neighbours[u_ad as usize][e] = t;
        }
        if t_bc != NONE {
            let e = self.edge_index(t_bc, c, b);
            self.neighbours[t_bc as usize][e] = u;
        }
        self.bounds[t as usize] = bounds[0].into();
        self.bounds[u as usize] = bounds[1].into();
        self.vertex_triangle[a as usize] = t;
        self.vertex_triangle[b as usize] = u;
        self.vertex_triangle[c as usize] = t;
        self.vertex_triangle[d as usize] = u;
    }

    /// Marks the vertices where the domain pinches: a vertex on one fan of triangles has
    /// zero or two domain-boundary edges, a vertex where several fans meet has more.
    fn mark_pinched(&mut self) {
        let mut boundary_edges = vec![0u8; self.vertex_triangle.len()];
        for (t, c) in self.corners.iter().enumerate() {
            if c[0] == NONE {
                continue;
            }
            for e in 0..3 {
                if self.neighbours[t][e] == NONE {
                    for v in [c[e], c[(e + 1) % 3]] {
                        boundary_edges[v as usize] = boundary_edges[v as usize].saturating_add(1);
                    }
                }
            }
        }
        for (p, &count) in self.pinched.iter_mut().zip(&boundary_edges) {
            *p = count > 2;
        }
    }

    /// Number of live triangles.
    pub(crate) fn triangle_count(&self) -> usize {
        self.live_triangles
    }

    /// Whether vertex `v` is in the mesh.
    pub(crate) fn contains_vertex(&self, v: u32) -> bool {
        self.vertex_triangle[v as usize] != NONE
    }

    /// Number of vertex slots (grid samples).
    pub(crate) fn vertex_slots(&self) -> usize {
        self.vertex_triangle.len()
    }

    /// Position and height of vertex `v` (see [`Vertices::point`]).
    #[inline]
    pub(crate) fn point(&self, v: u32) -> Point {
        self.samples.point(v)
    }

    /// Position and sample value at vertex `v`: what the TIN must come within the bound of
    /// there once `v` is gone.
    #[inline]
    pub(crate) fn sample_point(&self, v: u32) -> Point {
        self.samples.sample_point(v)
    }

    /// Bound of triangle `t`.
    pub(crate) fn bound(&self, t: u32) -> ErrorBound {
        self.bounds[t as usize].into()
    }

    /// Sets the bound of triangle `t` (stored rounded up, as every bound).
    pub(crate) fn set_bound(&mut self, t: u32, bound: ErrorBound) {
        self.bounds[t as usize] = bound.into();
    }

    /// Live triangles in slot order, as corner triples.
    pub(crate) fn live_triangles(&self) -> impl Iterator<Item = (u32, [u32; 3])> + '_ {
        self.corners
            .iter()
            .enumerate()
            .filter(|(_, c)| c[0] != NONE)
            .map(|(t, c)| (t as u32, *c))
    }

    /// Consumes the mesh: its live vertices (sample indices, increasing) and its live
    /// triangles (slot order) with corners renumbered as positions in that list. The links
    /// and bounds are freed first, so the result does not add to the mesh's peak memory.
    pub(crate) fn into_numbered(self) -> (Vec<u32>, Vec<[u32; 3]>) {
        let Mesh {
            corners,
            vertex_triangle,
            ..
        } = self;
        let mut number = vertex_triangle;
        let mut vertices = Vec::with_capacity(number.iter().filter(|&&t| t != NONE).count());
        for (v, n) in number.iter_mut().enumerate() {
            if *n != NONE {
                *n = vertices.len() as u32;
                vertices.push(v as u32);
            }
        }
        // Filtering and mapping in place reuses the corners' allocation.
        let mut triangles: Vec<[u32; 3]> = corners
            .into_iter()
            .filter(|c| c[0] != NONE)
            .map(|c| c.map(|v| number[v as usize]))
            .collect();
        triangles.shrink_to_fit();
        (vertices, triangles)
    }

    /// Fills `star` with the fan around `v` (which must be in the mesh).
    pub(crate) fn star(&self, v: u32, star: &mut Star) {
        star.ring.clear();
        star.triangles.clear();
        star.outer.clear();
        let start = self.vertex_triangle[v as usize];
        debug_assert_ne!(start, NONE);
        // Walk counter-clockwise from `start`; a closed fan comes back to it in one pass.
        let mut t = start;
        loop {
            let i = self.local(t, v);
            let c = self.corners[t as usize];
            star.ring.push(c[(i + 1) % 3]);
            star.triangles.push(t);
            star.outer.push(self.neighbours[t as usize][(i + 1) % 3]);
            let ccw = self.neighbours[t as usize][(i + 2) % 3];
            if ccw == NONE {
                star.ring.push(c[(i + 2) % 3]);
                break;
            }
            if ccw == start {
                // Begin at the triangle after `start`, as the decimation's tie-breaks
                // were measured with.
                star.open = false;
                star.triangles.rotate_left(1);
                star.outer.rotate_left(1);
                star.ring.rotate_left(1);
                return;
            }
            t = ccw;
        }
        // An open fan: the triangles clockwise of `start` come first.
        star.open = true;
        let ccw_triangles = star.triangles.len();
        let mut t = start;
        loop {
            let i = self.local(t, v);
            let cw = self.neighbours[t as usize][i];
            if cw == NONE {
                break;
            }
            let j = self.local(cw, v);
            star.ring.push(self.corners[cw as usize][(j + 1) % 3]);
            star.triangles.push(cw);
            star.outer.push(self.neighbours[cw as usize][(j + 1) % 3]);
            t = cw;
        }
        // The clockwise part was appended nearest-first: rotate it to the front, reversed.
        let cw_triangles = star.triangles.len() - ccw_triangles;
        if cw_triangles > 0 {
            star.triangles[ccw_triangles..].reverse();
            star.triangles.rotate_right(cw_triangles);
            star.outer[ccw_triangles..].reverse();
            star.outer.rotate_right(cw_triangles);
            let ring_ccw = ccw_triangles + 1;
            star.ring[ring_ccw..].reverse();
            star.ring.rotate_right(cw_triangles);
        }
    }

    /// Class of vertex `v` given its star (paper §3.2).
    pub(crate) fn classify(&self, v: u32, star: &Star) -> VertexClass {
        if self.pinched[v as usize] {
            return VertexClass::Corner;
        }
        if !star.open {
            return VertexClass::Interior;
        }
        let c = self.point(v);
        let a = self.point(star.ring[0]);
        let b = self.point(*star.ring.last().expect("a star has neighbours"));
        let straight =
            orient(&a, &c, &b) == 0 && (a.x - c.x) * (b.x - c.x) + (a.y - c.y) * (b.y - c.y) < 0;
        if straight {
            VertexClass::Boundary
        } else {
            VertexClass::Corner
        }
    }

    /// Replaces the star of `v` by `new_triangles` (corners index `star.ring`) and removes
    /// `v`. The new triangles must tile the star exactly.
    pub(crate) fn replace_star(
        &mut self,
        v: u32,
        star: &Star,
        new_triangles: &[(u32, [u32; 3], ErrorBound)],
    ) {
        // Ring edge i (ring[i] -> ring[i+1 mod m]) had star triangle i inside and
        // `star.outer[i]` outside; for an open star, edge m - 1 is the new domain edge that
        // replaces the two boundary edges through `v`.
        let m = star.ring.len();
        let outside_of = |a: u32, b: u32| {
            (0..m)
                .find(|&i| star.ring[i] == a && star.ring[(i + 1) % m] == b)
                .map(|i| star.outer.get(i).copied().unwrap_or(NONE))
                .expect("a hole edge is a ring edge or a shared diagonal")
        };
        debug_assert!(new_triangles.len() < star.triangles.len());
        for &t in &star.triangles {
            self.corners[t as usize] = [NONE; 3];
            self.neighbours[t as usize] = [NONE; 3];
        }
        for &(slot, c, bound) in new_triangles {
            self.corners[slot as usize] = c;
            self.bounds[slot as usize] = bound.into();
            for &x in &c {
                self.vertex_triangle[x as usize] = slot;
            }
        }
        // Link each new triangle edge to its twin: another new triangle, or the outside.
        for (n, &(slot, c, _)) in new_triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (c[e], c[(e + 1) % 3]);
                let twin = new_triangles
                    .iter()
                    .enumerate()
                    .find_map(|(m, &(s2, c2, _))| {
                        (m != n && (0..3).any(|k| c2[k] == b && c2[(k + 1) % 3] == a)).then_some(s2)
                    });
                let across = match twin {
                    Some(s2) => s2,
                    None => {
                        let outside = outside_of(a, b);
                        if outside != NONE {
                            let k = self.edge_index(outside, b, a);
                            self.neighbours[outside as usize][k] = slot;
                        }
                        outside
                    }
                };
                self.neighbours[slot as usize][e] = across;
            }
        }
        self.vertex_triangle[v as usize] = NONE;
        self.live_triangles -= star.triangles.len() - new_triangles.len();
    }

    /// Index of corner `v` in triangle `t`.
    fn local(&self, t: u32, v: u32) -> usize {
        let c = &self.corners[t as usize];
        if c[0] == v {
            0
        } else if c[1] == v {
            1
        } else {
            debug_assert_eq!(c[2], v, "vertex {v} not in triangle {t}");
            2
        }
    }

    /// Index of the edge `a -> b` in triangle `t`.
    fn edge_index(&self, t: u32, a: u32, b: u32) -> usize {
        let i = self.local(t, a);
        debug_assert_eq!(self.corners[t as usize][(i + 1) % 3], b);
        i
    }

    /// Checks every structural invariant; panics with a description on the first broken one.
    #[cfg(any(test, debug_assertions))]
    pub(crate) fn check_invariants(&self) {
        let mut live = 0;
        for (t, c) in self.live_triangles() {
            live += 1;
            let (a, b, cc) = (self.point(c[0]), self.point(c[1]), self.point(c[2]));
            assert!(
                orient(&a, &b, &cc) > 0,
                "triangle {t} {c:?} is not counter-clockwise"
            );
            for e in 0..3 {
                let n = self.neighbours[t as usize][e];
                if n != NONE {
                    let nc = self.corners[n as usize];
                    assert_ne!(nc[0], NONE, "triangle {t} links to dead triangle {n}");
                    let (x, y) = (c[e], c[(e + 1) % 3]);
                    assert!(
                        (0..3).any(|k| nc[k] == y && nc[(k + 1) % 3] == x),
                        "triangle {t} edge {e} and triangle {n} are not twins"
                    );
                }
            }
            for &v in &c {
                assert_ne!(
                    self.vertex_triangle[v as usize], NONE,
                    "vertex {v} lost its link"
                );
            }
        }
        assert_eq!(live, self.live_triangles, "live triangle count");
        for (v, &t) in self.vertex_triangle.iter().enumerate() {
            if t != NONE {
                assert!(
                    self.corners[t as usize].contains(&(v as u32)),
                    "vertex {v} link"
                );
            }
        }
    }
}

impl Mesh<'_, Grid> {
    /// Grid columns.
    pub(crate) fn width(&self) -> u32 {
        self.samples.width()
    }

    /// Grid rows.
    pub(crate) fn height(&self) -> u32 {
        self.samples.height()
    }

    /// Samples per grid row (vertex `v` sits at column `v % width`, row `v / width`).
    pub(crate) fn grid_width(&self) -> usize {
        self.samples.width() as usize
    }
}

impl<'g, V: Vertices + ?Sized> Mesh<'g, V> {
    /// A mesh from counter-clockwise triangles over `samples`' vertices that form a
    /// conforming triangulation, all bounds zero. Neighbours are found by sorting the
    /// directed edges (12 bytes per edge while linking).
    pub(crate) fn from_conforming(samples: &'g V, corners: Vec<[u32; 3]>) -> Mesh<'g, V> {
        let n = samples.vertex_count();
        let mut edges: Vec<(u64, u32)> = Vec::with_capacity(3 * corners.len());
        for (t, c) in corners.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (c[e], c[(e + 1) % 3]);
                // The undirected edge's key, the triangle and which edge it is.
                let key = u64::from(a.min(b)) << 32 | u64::from(a.max(b));
                edges.push((key, (t as u32) << 2 | e as u32));
            }
        }
        edges.sort_unstable();
        let mut neighbours = vec![[NONE; 3]; corners.len()];
        for pair in edges.windows(2) {
            if pair[0].0 == pair[1].0 {
                let (t, e) = ((pair[0].1 >> 2) as usize, (pair[0].1 & 3) as usize);
                let (u, k) = ((pair[1].1 >> 2) as usize, (pair[1].1 & 3) as usize);
                neighbours[t][e] = u as u32;
                neighbours[u][k] = t as u32;
            }
        }
        drop(edges);
        let mut vertex_triangle = vec![NONE; n];
        for (t, c) in corners.iter().enumerate() {
            for &v in c {
                vertex_triangle[v as usize] = t as u32;
            }
        }
        let live = corners.len();
        let mut mesh = Mesh {
            samples,
            bounds: vec![CompactBound::default(); corners.len()],
            corners,
            neighbours,
            vertex_triangle,
            pinched: vec![false; n],
            live_triangles: live,
        };
        mesh.mark_pinched();
        mesh
    }
}
