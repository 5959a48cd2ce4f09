//! An existing TIN's vertices as points on a lattice, with its own triangles checked to be
//! a valid planar triangulation by exact integer predicates.
//!
//! # The lattice
//! Per axis, the step is the coarsest power of ten `10^-d`, `d` in `0..=12`, on which
//! every coordinate is a lattice point: `|x - k 10^-d| <= 10^-6 10^-d + 8 ε |x|` for an
//! integer `k` (a millionth of a step, plus `f64` rounding of the written value). When no
//! power of ten holds them within [`MAX_LATTICE`] steps, the coordinates' own regular
//! spacing `g` (the smallest gap between distinct values; every value `min + k g` within
//! a millionth of `g` and `f64` rounding) is the step: a grid of 1/1200 degree, say.
//! Lattice position 0 is the smallest x and y. Coordinates on neither, or spanning more
//! than [`MAX_LATTICE`] steps, are refused. Scaling an axis keeps every orientation's
//! sign, so the exact predicates decide on the lattice what they would on the file.

use std::path::Path;

use crate::cloud::{ClassChoice, FileCrs, PointCloud, MAX_LATTICE};
use crate::error::{format_error, Result};

/// The finest lattice step tried: `10^-MAX_DECIMALS`.
const MAX_DECIMALS: i32 = 12;

/// A TIN's vertices as lattice points and its triangles over them.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TinPoints {
    /// The vertices used by some triangle (identical copies merged), on the lattice.
    pub cloud: PointCloud,
    /// Each point's x, y, z exactly as the file has them.
    pub world: Vec<[f64; 3]>,
    /// The file's triangles over the points, counter-clockwise on the lattice (x right,
    /// y up): every triangle of the file, flipped when the file winds them clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Vertices of the file no triangle uses (dropped).
    pub unused: usize,
    /// Copies of a vertex (same x, y, z) merged into one.
    pub merged: usize,
}

/// Puts the TIN `vertices`, `triangles` (0-based indices) of the file `path` on a lattice
/// and checks that the triangles are a valid planar triangulation.
///
/// # Errors
/// [`crate::Error::Format`] naming `path` and the problem: no triangles, a non-finite
/// coordinate, an index out of range, coordinates no power-of-ten lattice holds within
/// 2^31 steps, two vertices at the same x, y with different heights, a degenerate
/// triangle (zero area or a repeated corner), triangles wound both ways (a fold), an edge
/// with two triangles on the same side, or two triangles that overlap or touch other than
/// at shared vertices and edges.
pub fn tin_points(path: &Path, vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<TinPoints> {
    let problem = |text: String| format_error(path, text);
    if triangles.is_empty() {
        return Err(problem("the file has no triangles".into()));
    }
    let n = vertices.len();
    let mut used = vec![false; n];
    for (t, c) in triangles.iter().enumerate() {
        for &v in c {
            if v as usize >= n {
                return Err(problem(format!(
                    "triangle {t} names vertex {v}; the file has {n}"
                )));
            }
            used[v as usize] = true;
        }
    }
    if let Some((i, v)) = vertices
        .iter()
        .enumerate()
        .find(|(i, v)| used[*i] && v.iter().any(|c| !c.is_finite()))
    {
        return Err(problem(format!("vertex {i} ({v:?}) is not finite")));
    }
    let ids: Vec<usize> = (0..n).filter(|&i| used[i]).collect();
    let unused = n - ids.len();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &i in &ids {
        for a in 0..2 {
            lo[a] = lo[a].min(vertices[i][a]);
            hi[a] = hi[a].max(vertices[i][a]);
        }
    }
    let mut scale = [0.0f64; 2];
    for a in 0..2 {
        let values: Vec<f64> = ids.iter().map(|&i| vertices[i][a]).collect();
        scale[a] = axis_scale(&values, lo[a], hi[a])
            .map_err(|why| problem(format!("{}: {why}", ["x", "y"][a])))?;
    }
    let lattice = |p: &[f64; 3]| {
        [
            ((p[0] - lo[0]) * scale[0]).round() as i64,
            ((p[1] - lo[1]) * scale[1]).round() as i64,
        ]
    };
    // Sorted by lattice position (then file order): equal positions are neighbours.
    let mut order: Vec<(i64, i64, usize)> = ids
        .iter()
        .map(|&i| {
            let [x, y] = lattice(&vertices[i]);
            (x, y, i)
        })
        .collect();
    order.sort_unstable();
    let mut point_of = vec![u32::MAX; n];
    let (mut xy, mut z, mut world) = (Vec::new(), Vec::new(), Vec::new());
    let mut merged = 0;
    for (k, &(x, y, i)) in order.iter().enumerate() {
        if k > 0 && (order[k - 1].0, order[k - 1].1) == (x, y) {
            let j = order[k - 1].2;
            let first = point_of[j];
            if vertices[i] != world[first as usize] {
                return Err(problem(format!(
                    "vertices {j} {:?} and {i} {:?} are at the same x, y: a TIN holds one \
                     height there",
                    vertices[j], vertices[i]
                )));
            }
            point_of[i] = first;
            merged += 1;
            continue;
        }
        point_of[i] = xy.len() as u32;
        xy.push([x, y]);
        z.push(vertices[i][2]);
        world.push(vertices[i]);
    }
    let mut corners: Vec<[u32; 3]> = triangles
        .iter()
        .map(|c| c.map(|v| point_of[v as usize]))
        .collect();
    let orient = |c: &[u32; 3]| orient(xy[c[0] as usize], xy[c[1] as usize], xy[c[2] as usize]);
    let mut winding: Option<(usize, i64)> = None;
    for (t, c) in corners.iter().enumerate() {
        let o = orient(c);
        if o == 0 {
            return Err(problem(format!(
                "triangle {t} {:?} is degenerate (no area)",
                triangles[t]
            )));
        }
        match winding {
            None => winding = Some((t, o.signum())),
            Some((first, sign)) if sign != o.signum() => {
                return Err(problem(format!(
                    "triangles {first} and {t} wind in opposite directions: the surface is \
                     folded or has flipped triangles"
                )))
            }
            _ => {}
        }
    }
    if winding.is_some_and(|(_, sign)| sign < 0) {
        for c in &mut corners {
            c.swap(1, 2);
        }
    }
    check_edges(&corners).map_err(|(s, t)| {
        problem(format!(
            "triangles {s} and {t} lie on the same side of a shared edge: they overlap"
        ))
    })?;
    check_overlaps(&xy, &corners).map_err(|(s, t)| {
        problem(format!(
            "triangles {s} and {t} overlap (or one's corner lies on the other without \
             being its corner)"
        ))
    })?;
    let points_in_file = n as u64;
    Ok(TinPoints {
        cloud: PointCloud {
            xy,
            z,
            origin: lo,
            spacing: [1.0 / scale[0], 1.0 / scale[1]],
            crs: FileCrs::default(),
            classes: ClassChoice::All,
            points_in_file,
        },
        world,
        triangles: corners,
        unused,
        merged,
    })
}

/// Lattice steps per world unit along one axis of coordinates `values` (smallest `lo`,
/// largest `hi`): `10^d` for the coarsest power-of-ten step holding every value, else
/// `1 / g` for the regular spacing `g` of the values (the smallest gap between distinct
/// values, every value `lo + k g`), with the span at most [`MAX_LATTICE`] steps either
/// way; why not otherwise.
pub(crate) fn axis_scale(values: &[f64], lo: f64, hi: f64) -> std::result::Result<f64, String> {
    let fits = |per_unit: f64| ((hi - lo) * per_unit).round() <= MAX_LATTICE as f64;
    let decimals = (0..=MAX_DECIMALS).find(|&d| values.iter().all(|&v| on_lattice(v, d)));
    if let Some(d) = decimals {
        if fits(10f64.powi(d)) {
            return Ok(10f64.powi(d));
        }
    }
    // A regular spacing that is no power of ten (a grid of 1/1200 degree, say).
    let noise = |a: f64, b: f64| 16.0 * f64::EPSILON * (a.abs() + b.abs());
    let mut sorted = values.to_vec();
    sorted.sort_unstable_by(f64::total_cmp);
    let gap = sorted
        .windows(2)
        .filter(|w| w[1] - w[0] > noise(w[0], w[1]))
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    let regular = gap.is_finite()
        && values.iter().all(|&v| {
            let k = ((v - lo) / gap).round();
            (v - lo - k * gap).abs() <= 1e-6 * gap + noise(v, lo)
        });
    if regular && fits(1.0 / gap) {
        return Ok(1.0 / gap);
    }
    Err(match decimals {
        Some(d) => format!(
            "the vertices span {} at a lattice step of 1e-{d} (the coarsest power of ten holding their coordinates): more than {MAX_LATTICE} steps, beyond the exact integer geometry, and they are on no coarser regular spacing",
            hi - lo
        ),
        None => format!(
            "the coordinates are on no power-of-ten step down to 1e-{MAX_DECIMALS} and on no regular spacing within {MAX_LATTICE} steps, so the exact integer geometry cannot hold them"
        ),
    })
}

/// Whether `x` is a multiple of `10^-decimals`, within a millionth of a step and `f64`
/// rounding.
fn on_lattice(x: f64, decimals: i32) -> bool {
    let step = 10f64.powi(-decimals);
    let k = (x / step).round();
    (x - k * step).abs() <= 1e-6 * step + 8.0 * f64::EPSILON * x.abs()
}

/// Twice the signed area of `a`, `b`, `c`: positive counter-clockwise. Exact: coordinates
/// are in `0..=MAX_LATTICE`, so each product is below 2^62.
fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Each directed edge of counter-clockwise triangles at most once (else two triangles are
/// on the same side of it); the two triangles on failure.
fn check_edges(corners: &[[u32; 3]]) -> std::result::Result<(), (usize, usize)> {
    let mut edges: Vec<(u32, u32, usize)> = corners
        .iter()
        .enumerate()
        .flat_map(|(t, c)| (0..3).map(move |e| (c[e], c[(e + 1) % 3], t)))
        .collect();
    edges.sort_unstable();
    match edges
        .windows(2)
        .find(|w| (w[0].0, w[0].1) == (w[1].0, w[1].1))
    {
        Some(w) => Err((w[0].2, w[1].2)),
        None => Ok(()),
    }
}

/// No two triangles' interiors meet and no corner lies in a triangle it is not a corner
/// of; the two triangles on failure. Triangles are bucketed by their bounding boxes on a
/// grid of about one cell per triangle, and each pair sharing a cell is tested once (in
/// the first cell both cover) with exact predicates.
///
/// # Runtime
/// About linear for triangles of similar sizes (on 2.0 M triangles of a grid, the whole
/// of [`tin_points`] is about a sixth of a `mesh` run at 0.1 m, the PLY read a fiftieth);
/// quadratic in the triangles sharing one cell, so a fan of very many slivers around one
/// point is slow.
fn check_overlaps(
    xy: &[[i64; 2]],
    corners: &[[u32; 3]],
) -> std::result::Result<(), (usize, usize)> {
    let boxes: Vec<[i64; 4]> = corners
        .iter()
        .map(|c| {
            let p = c.map(|v| xy[v as usize]);
            [
                p.iter().map(|q| q[0]).min().unwrap_or(0),
                p.iter().map(|q| q[1]).min().unwrap_or(0),
                p.iter().map(|q| q[0]).max().unwrap_or(0),
                p.iter().map(|q| q[1]).max().unwrap_or(0),
            ]
        })
        .collect();
    let width = xy.iter().map(|p| p[0]).max().unwrap_or(0) + 1;
    let height = xy.iter().map(|p| p[1]).max().unwrap_or(0) + 1;
    // Cells about the size of an average triangle's box.
    let mean_box = boxes
        .iter()
        .map(|b| ((b[2] - b[0] + 1) as f64 * (b[3] - b[1] + 1) as f64).sqrt())
        .sum::<f64>()
        / boxes.len() as f64;
    let mut cell = (mean_box.ceil() as i64).max(1);
    // Long slivers could cover many cells each: coarser cells until the bucket entries
    // are at most 16 per triangle (or one cell holds everything), so memory stays linear.
    let limit = 16 * boxes.len() as u64 + 1024;
    let entries = |cell: i64| -> u64 {
        boxes
            .iter()
            .map(|b| ((b[2] / cell - b[0] / cell + 1) * (b[3] / cell - b[1] / cell + 1)) as u64)
            .sum()
    };
    while entries(cell) > limit && cell < width.max(height) {
        cell *= 2;
    }
    let (cols, rows) = ((width + cell - 1) / cell, (height + cell - 1) / cell);
    let cells_of = |b: &[i64; 4]| (b[0] / cell, b[1] / cell, b[2] / cell, b[3] / cell);
    let mut start = vec![0usize; (cols * rows + 1) as usize];
    for b in &boxes {
        let (x0, y0, x1, y1) = cells_of(b);
        for y in y0..=y1 {
            for x in x0..=x1 {
                start[(y * cols + x) as usize + 1] += 1;
            }
        }
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; start[start.len() - 1]];
    for (t, b) in boxes.iter().enumerate() {
        let (x0, y0, x1, y1) = cells_of(b);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let k = (y * cols + x) as usize;
                members[fill[k]] = t as u32;
                fill[k] += 1;
            }
        }
    }
    for k in 0..(cols * rows) as usize {
        let (cx, cy) = (k as i64 % cols, k as i64 / cols);
        let list = &members[start[k]..start[k + 1]];
        for (i, &s) in list.iter().enumerate() {
            for &t in &list[i + 1..] {
                let (a, b) = (&boxes[s as usize], &boxes[t as usize]);
                if a[0] > b[2] || b[0] > a[2] || a[1] > b[3] || b[1] > a[3] {
                    continue;
                }
                // Tested only in the first cell both boxes cover.
                if (a[0].max(b[0]) / cell, a[1].max(b[1]) / cell) != (cx, cy) {
                    continue;
                }
                let (p, q) = (corners[s as usize], corners[t as usize]);
                if overlap(xy, p, q) {
                    return Err((s.min(t) as usize, s.max(t) as usize));
                }
            }
        }
    }
    Ok(())
}

/// Whether counter-clockwise triangles `p` and `q` overlap: their interiors meet (no edge
/// of either separates them) or a corner of one lies in the closed other without being
/// its corner.
fn overlap(xy: &[[i64; 2]], p: [u32; 3], q: [u32; 3]) -> bool {
    let at = |v: u32| xy[v as usize];
    let separates = |a: [u32; 3], b: [u32; 3]| {
        (0..3).any(|e| {
            let (u, v) = (at(a[e]), at(a[(e + 1) % 3]));
            b.iter().all(|&w| orient(u, v, at(w)) <= 0)
        })
    };
    let corner_inside = |a: [u32; 3], b: [u32; 3]| {
        b.iter().any(|&w| {
            !a.contains(&w) && (0..3).all(|e| orient(at(a[e]), at(a[(e + 1) % 3]), at(w)) >= 0)
        })
    };
    !(separates(p, q) || separates(q, p)) || corner_inside(p, q) || corner_inside(q, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<TinPoints> {
        tin_points(Path::new("t.ply"), vertices, triangles)
    }

    /// A unit square of two triangles.
    fn square() -> Vec<[f64; 3]> {
        vec![
            [10.5, 20.0, 1.0],
            [11.5, 20.0, 2.0],
            [11.5, 21.0, 3.0],
            [10.5, 21.0, 4.0],
        ]
    }

    #[test]
    fn lattice_is_the_coarsest_power_of_ten() {
        let t = read(&square(), &[[0, 1, 2], [0, 2, 3]]).unwrap();
        assert_eq!(t.cloud.spacing, [0.1, 1.0]);
        assert_eq!(t.cloud.origin, [10.5, 20.0]);
        assert_eq!(t.cloud.xy, vec![[0, 0], [0, 1], [10, 0], [10, 1]]);
        assert_eq!(t.world[1], [10.5, 21.0, 4.0]);
        assert_eq!(t.triangles.len(), 2);
        let mut v = square();
        v[0][0] = 10.25;
        assert_eq!(
            read(&v, &[[0, 1, 2], [0, 2, 3]]).unwrap().cloud.spacing,
            [0.01, 1.0]
        );
        v[0][0] = 10.0 + std::f64::consts::PI / 10.0;
        let e = read(&v, &[[0, 1, 2], [0, 2, 3]]).unwrap_err().to_string();
        assert!(
            e.contains("t.ply") && e.contains("x: ") && e.contains("regular"),
            "{e}"
        );
    }

    #[test]
    fn a_grid_of_no_power_of_ten_gets_its_own_spacing() {
        // 3 arc-second samples, as a geographic DEM gives them.
        let step = 1.0 / 1200.0;
        let mut v = Vec::new();
        for r in 0..3 {
            for c in 0..3 {
                v.push([-120.0 + c as f64 * step, 45.0 + r as f64 * step, 1.0]);
            }
        }
        let t = read(&v, &[[0, 1, 4], [0, 4, 3], [4, 5, 8], [1, 2, 5]]).unwrap();
        assert!(
            (t.cloud.spacing[0] - step).abs() < 1e-15,
            "{:?}",
            t.cloud.spacing
        );
        assert!(t.cloud.xy.iter().all(|p| p[0] <= 2 && p[1] <= 2));
    }

    #[test]
    fn clockwise_files_are_flipped_and_unused_vertices_dropped() {
        let mut v = square();
        v.push([50.0, 50.0, 0.0]);
        let t = read(&v, &[[0, 2, 1], [0, 3, 2]]).unwrap();
        assert_eq!(t.unused, 1);
        for c in &t.triangles {
            let p = c.map(|v| t.cloud.xy[v as usize]);
            assert!(orient(p[0], p[1], p[2]) > 0);
        }
    }

    #[test]
    fn identical_copies_merge_and_conflicting_heights_are_refused() {
        let mut v = square();
        v.push(v[2]);
        let t = read(&v, &[[0, 1, 2], [0, 4, 3]]).unwrap();
        assert_eq!((t.merged, t.cloud.xy.len()), (1, 4));
        v[4][2] = 9.0;
        let e = read(&v, &[[0, 1, 2], [0, 4, 3]]).unwrap_err().to_string();
        assert!(e.contains("vertices 2") && e.contains("same x, y"), "{e}");
    }

    #[test]
    fn bad_triangulations_are_refused() {
        let v = square();
        let e = |t: &[[u32; 3]]| read(&v, t).unwrap_err().to_string();
        assert!(e(&[[0, 1, 2], [0, 3, 2]]).contains("opposite directions"));
        assert!(e(&[[0, 1, 1]]).contains("degenerate"));
        assert!(e(&[[0, 1, 2], [0, 1, 3]]).contains("same side"));
        // Both diagonals' triangles: they cross.
        assert!(e(&[[0, 1, 2], [0, 2, 3], [0, 1, 3]]).contains("overlap"));
        assert!(e(&[]).contains("no triangles"));
        assert!(e(&[[0, 1, 7]]).contains("names vertex 7"));
        // A corner on another triangle's edge (a T-junction).
        let mut v = square();
        v.push([11.0, 20.5, 0.0]);
        let t = [[0, 1, 2], [0, 4, 3], [4, 2, 3]];
        let e = read(&v, &t).unwrap_err().to_string();
        assert!(e.contains("overlap"), "{e}");
        // Two separate stacked triangles.
        let w = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let e = read(&w, &[[0, 1, 2], [3, 4, 5]]).unwrap_err().to_string();
        assert!(e.contains("triangles 0 and 1 overlap"), "{e}");
    }

    #[test]
    fn long_slivers_keep_the_buckets_small() {
        // A fan of 200 slivers from one corner to a far row of points: every sliver's box
        // spans the whole width, which needs coarser cells.
        let mut v = vec![[0.0, 0.0, 0.0]];
        for i in 0..=200 {
            v.push([1000.0, i as f64, 0.0]);
        }
        let t: Vec<[u32; 3]> = (1..=200).map(|i| [0, i, i + 1]).collect();
        assert_eq!(read(&v, &t).unwrap().triangles.len(), 200);
        let mut t = t;
        t.push([0, 1, 201]);
        let e = read(&v, &t).unwrap_err().to_string();
        assert!(e.contains("overlap") || e.contains("same side"), "{e}");
    }

    #[test]
    fn a_ring_with_a_hole_is_valid() {
        // A 3 x 3 square with the middle unit square missing.
        let mut v = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                v.push([x as f64, y as f64, (x * y) as f64]);
            }
        }
        let mut t = Vec::new();
        for y in 0..3u32 {
            for x in 0..3u32 {
                if (x, y) == (1, 1) {
                    continue;
                }
                let a = y * 4 + x;
                t.push([a, a + 1, a + 5]);
                t.push([a, a + 5, a + 4]);
            }
        }
        let r = read(&v, &t).unwrap();
        assert_eq!((r.triangles.len(), r.cloud.xy.len()), (16, 16));
    }
}
