//! Breaklines against a TIN: each segment must be a chain of mesh edges, found by walking
//! the mesh's own vertex adjacency, sharing nothing with the triangulation that built it.

use serde::Serialize;

/// What checking breaklines against a TIN found.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct BreaklinesReport {
    /// Segments checked (consecutive distinct vertices of every line).
    pub segments: usize,
    /// Segments that are not a chain of mesh edges.
    pub missing: usize,
    /// The first missing segment, as world `[x, y]` ends.
    pub first_missing: Option<[[f64; 2]; 2]>,
    /// How far (x, y) a chain's vertex may lie from its segment.
    pub tolerance: f64,
}

impl BreaklinesReport {
    /// Whether every segment is present.
    pub fn passed(&self) -> bool {
        self.missing == 0
    }
}

/// Checks that every segment of every line (world `[x, y]`, consecutive vertices) is a
/// chain of edges of the TIN `vertices` / `triangles`: from the mesh vertex at its start
/// to the one at its end (each within `tolerance`), through edges whose ends all lie
/// within `tolerance` of the segment and advance along it. `tolerance` allows for a
/// lattice the mesh's vertices were rounded to, or a float32 format; 0 asks for exact
/// positions (up to the rounding of the `f64` arithmetic, a few ulps of the coordinates).
///
/// # Panics
/// When a triangle names a vertex that does not exist.
pub fn verify_breaklines(
    lines: &[Vec<[f64; 2]>],
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    tolerance: f64,
) -> BreaklinesReport {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); vertices.len()];
    for t in triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let mut by_x: Vec<u32> = (0..vertices.len() as u32)
        .filter(|&v| !neighbours[v as usize].is_empty())
        .collect();
    by_x.sort_by(|&a, &b| vertices[a as usize][0].total_cmp(&vertices[b as usize][0]));
    let nearest = |p: [f64; 2]| -> Option<u32> {
        let start = by_x.partition_point(|&v| vertices[v as usize][0] < p[0] - tolerance);
        by_x[start..]
            .iter()
            .take_while(|&&v| vertices[v as usize][0] <= p[0] + tolerance)
            .map(|&v| {
                let q = vertices[v as usize];
                ((q[0] - p[0]).hypot(q[1] - p[1]), v)
            })
            .filter(|&(d, _)| d <= tolerance)
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .map(|(_, v)| v)
    };
    let mut report = BreaklinesReport {
        segments: 0,
        missing: 0,
        first_missing: None,
        tolerance,
    };
    for line in lines {
        for pair in line.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let length = (b[0] - a[0]).hypot(b[1] - a[1]);
            if length == 0.0 {
                continue;
            }
            report.segments += 1;
            let present = match (nearest(a), nearest(b)) {
                (Some(start), Some(end)) => {
                    walk(a, b, length, start, end, vertices, &neighbours, tolerance)
                }
                _ => false,
            };
            if !present {
                report.missing += 1;
                report.first_missing.get_or_insert([a, b]);
            }
        }
    }
    report
}

/// Whether edges lead from `start` to `end` along the segment `a`-`b`: at each vertex the
/// neighbour within `tolerance` of the segment that is furthest along it (and ahead).
#[allow(clippy::too_many_arguments)]
fn walk(
    a: [f64; 2],
    b: [f64; 2],
    length: f64,
    start: u32,
    end: u32,
    vertices: &[[f64; 3]],
    neighbours: &[Vec<u32>],
    tolerance: f64,
) -> bool {
    let dir = [(b[0] - a[0]) / length, (b[1] - a[1]) / length];
    let along = |v: u32| {
        let q = vertices[v as usize];
        (q[0] - a[0]) * dir[0] + (q[1] - a[1]) * dir[1]
    };
    let off = |v: u32| {
        let q = vertices[v as usize];
        ((q[0] - a[0]) * dir[1] - (q[1] - a[1]) * dir[0]).abs()
    };
    // Rounding of the products above: a few ulps of the coordinates' magnitude.
    let scale = a[0].abs().max(a[1].abs()).max(b[0].abs()).max(b[1].abs()) + length;
    let tolerance = tolerance + 8.0 * f64::EPSILON * scale;
    let mut at = start;
    // Each step moves strictly ahead, so no vertex is visited twice.
    for _ in 0..vertices.len() {
        if at == end {
            return true;
        }
        let here = along(at);
        let next = neighbours[at as usize]
            .iter()
            .copied()
            .filter(|&w| off(w) <= tolerance && along(w) > here && along(w) <= length + tolerance)
            .max_by(|&v, &w| along(v).total_cmp(&along(w)).then(w.cmp(&v)));
        match next {
            Some(w) => at = w,
            None => return false,
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 x 3 lattice of unit squares, each split along its rising diagonal.
    fn lattice() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                v.push([f64::from(x), f64::from(y), 0.0]);
            }
        }
        let mut t = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                let a = y * 4 + x;
                t.push([a, a + 1, a + 5]);
                t.push([a, a + 5, a + 4]);
            }
        }
        (v, t)
    }

    #[test]
    fn chains_along_rows_and_diagonals_are_found() {
        let (v, t) = lattice();
        let lines = vec![
            vec![[0.0, 0.0], [3.0, 0.0], [3.0, 3.0]],
            vec![[0.0, 0.0], [3.0, 3.0]],
            vec![[0.0, 1.0], [3.0, 1.0]],
        ];
        let r = verify_breaklines(&lines, &v, &t, 0.0);
        assert_eq!((r.segments, r.missing), (4, 0), "{r:?}");
        assert!(r.passed());
    }

    #[test]
    fn a_segment_across_triangles_or_off_the_vertices_is_missing() {
        let (v, t) = lattice();
        // The falling diagonal crosses every rising one: no chain of edges.
        let r = verify_breaklines(&[vec![[0.0, 3.0], [3.0, 0.0]]], &v, &t, 0.0);
        assert_eq!(r.missing, 1);
        assert_eq!(r.first_missing, Some([[0.0, 3.0], [3.0, 0.0]]));
        // An end between vertices, unless the tolerance reaches one.
        let off = vec![vec![[0.0, 0.0], [2.01, 0.0]]];
        assert_eq!(verify_breaklines(&off, &v, &t, 0.0).missing, 1);
        assert_eq!(verify_breaklines(&off, &v, &t, 0.02).missing, 0);
        // A knight's move is not a chain even if its ends are vertices.
        assert!(!verify_breaklines(&[vec![[0.0, 0.0], [1.0, 2.0]]], &v, &t, 0.0).passed());
    }
}
