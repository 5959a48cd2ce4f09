//! Property tests on random small grids (with nodata holes, flats, quantized values, levels
//! exactly at sample values), on the full grid and on decimated TINs: every point lies on a
//! mesh edge at its level, lines end only on boundary edges, rings are closed, every
//! crossing is used exactly once, the high ground is on the left, and the output is
//! deterministic. The checks recompute everything from the mesh and share no code with the
//! contouring.

use std::collections::HashMap;

use proptest::prelude::*;
use tinsmith_contour::{contour, ContourMesh, Polyline};
use tinsmith_testkit::{max_error, small_grid, GridSpec, SplitMix};

mod common;
use common::{levels_for, meshes};

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

fn check(mesh: &ContourMesh, levels: &[f64]) -> Result<(), TestCaseError> {
    let vs = mesh.vertices();
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for t in mesh.triangles() {
        for k in 0..3 {
            *uses.entry(key(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let lines = contour(mesh, levels).unwrap();
    // Deterministic, and independent of the order of the levels.
    let mut rev = levels.to_vec();
    rev.reverse();
    prop_assert_eq!(&contour(mesh, &rev).unwrap(), &lines);

    let mut seen: HashMap<(u64, (u32, u32)), usize> = HashMap::new();
    let mut segments = std::collections::HashSet::new();
    let mut prev: Option<(f64, [u32; 2])> = None;
    for line in &lines {
        let level = line.level();
        let (pts, edges) = (line.points(), line.edges());
        prop_assert_eq!(pts.len(), edges.len());
        // Order: by level, then by the first point's edge.
        if let Some(p) = prev {
            prop_assert!(
                p < (level, edges[0]),
                "order {:?} then {:?}",
                p,
                (level, edges[0])
            );
        }
        prev = Some((level, edges[0]));
        if line.is_closed() {
            prop_assert!(pts.len() >= 3);
            prop_assert_eq!(pts.first(), pts.last());
            prop_assert_eq!(edges.first(), edges.last());
        } else {
            prop_assert!(pts.len() >= 2);
        }
        for w in pts.windows(2) {
            prop_assert_ne!(w[0], w[1], "repeated point");
            // Every segment once per level, in either direction: none along a ridge at
            // the level twice (once by each line beside it).
            let ends = |p: [f64; 2]| [p[0].to_bits(), p[1].to_bits()];
            let (a, b) = (ends(w[0]), ends(w[1]));
            let segment = (level.to_bits(), a.min(b), a.max(b));
            prop_assert!(segments.insert(segment), "segment {:?} twice", w);
        }
        let n = pts.len();
        for (i, (&p, &[a, b])) in pts.iter().zip(edges).enumerate() {
            prop_assert!(a < b);
            let count = uses.get(&(a, b)).copied().unwrap_or(0);
            let end = !line.is_closed() && (i == 0 || i == n - 1);
            // Ends of open lines on boundary edges, everything else on interior edges.
            prop_assert_eq!(
                count,
                if end { 1 } else { 2 },
                "edge ({}, {}) point {}",
                a,
                b,
                i
            );
            // On the edge, at the level: one end below, the other at or above; the point is
            // the interpolated crossing.
            let (pa, pb) = (vs[a as usize], vs[b as usize]);
            let (lo, hi) = if pa[2] < level { (pa, pb) } else { (pb, pa) };
            prop_assert!(lo[2] < level && level <= hi[2], "edge does not straddle");
            let d = [hi[0] - lo[0], hi[1] - lo[1]];
            let s = if d[0].abs() >= d[1].abs() {
                (p[0] - lo[0]) / d[0]
            } else {
                (p[1] - lo[1]) / d[1]
            };
            prop_assert!((0.0..=1.0).contains(&s), "off the edge: s = {}", s);
            let off_line = (p[0] - lo[0]) * d[1] - (p[1] - lo[1]) * d[0];
            prop_assert!(off_line.abs() <= 1e-9 * (1.0 + d[0].abs() + d[1].abs()));
            let z = lo[2] + s * (hi[2] - lo[2]);
            let scale = 1.0 + lo[2].abs().max(hi[2].abs());
            prop_assert!(
                (z - level).abs() <= 1e-9 * scale,
                "z {} at level {}",
                z,
                level
            );
            if s == 1.0 {
                prop_assert_eq!(
                    p,
                    [hi[0], hi[1]],
                    "a crossing at the upper end is the vertex"
                );
            }
            // High ground on the left of each segment leaving this point.
            if i + 1 < n && p != [hi[0], hi[1]] {
                let q = pts[i + 1];
                let side = (q[0] - p[0]) * (hi[1] - p[1]) - (q[1] - p[1]) * (hi[0] - p[0]);
                prop_assert!(side >= -1e-9, "upper end of ({}, {}) on the right", a, b);
            }
            if !(line.is_closed() && i == n - 1) {
                *seen.entry((level.to_bits(), (a, b))).or_default() += 1;
            }
        }
    }
    // Completeness: every crossed edge whose crossing is not at a vertex is on exactly one
    // line (crossings at a vertex on the level may be merged into a neighbour's point).
    let mut sorted = levels.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    for &(a, b) in uses.keys() {
        let (pa, pb) = (vs[a as usize], vs[b as usize]);
        for &level in &sorted {
            let straddles = (pa[2] < level) != (pb[2] < level);
            let at_vertex = pa[2] == level || pb[2] == level;
            let used = seen.get(&(level.to_bits(), (a, b))).copied().unwrap_or(0);
            if straddles && !at_vertex {
                prop_assert_eq!(
                    used,
                    1,
                    "edge ({}, {}) at {} used {} times",
                    a,
                    b,
                    level,
                    used
                );
            } else {
                prop_assert!(used <= 1);
                prop_assert!(straddles || used == 0);
            }
        }
    }
    Ok(())
}

proptest! {
    #[test]
    fn contours_lie_on_the_tin_and_join_properly(
        spec in small_grid(),
        e in max_error(),
        seed in any::<u64>(),
    ) {
        let levels = levels_for(&spec, seed);
        for mesh in meshes(&spec, e) {
            check(&mesh, &levels)?;
        }
    }
}

#[test]
fn terrain_with_holes_at_many_levels() {
    let spec = tinsmith_testkit::with_nodata_disc(
        tinsmith_testkit::terrain(60, 45, 4.0, 7),
        20.0,
        20.0,
        6.0,
    );
    let levels: Vec<f64> = (0..40).map(|k| 300.0 + 12.5 * k as f64).collect();
    for mesh in meshes(&spec, 2.0) {
        check(&mesh, &levels).unwrap();
    }
    // Quantized heights: levels land exactly on many samples.
    let q = GridSpec {
        values: spec
            .values
            .iter()
            .map(|v| (v / 10.0).round() * 10.0)
            .collect(),
        ..spec
    };
    let levels: Vec<f64> = (0..80).map(|k| 300.0 + 10.0 * k as f64).collect();
    for mesh in meshes(&q, 0.0) {
        check(&mesh, &levels).unwrap();
    }
    let lines: Vec<Polyline> = contour(&meshes(&q, 0.0)[0], &levels).unwrap();
    assert!(lines.iter().any(Polyline::is_closed) && lines.iter().any(|l| !l.is_closed()));
}

/// The lines as a set that ignores vertex numbering: each ring turned into its smallest
/// rotation (a ring through a saddle vertex at the level visits that point twice, so its
/// smallest point alone does not fix where it starts), all sorted.
fn canonical(lines: &[Polyline]) -> Vec<(u64, bool, Vec<[u64; 2]>)> {
    let mut out: Vec<(u64, bool, Vec<[u64; 2]>)> = lines
        .iter()
        .map(|l| {
            let mut points: Vec<[u64; 2]> = l
                .points()
                .iter()
                .map(|p| [p[0].to_bits(), p[1].to_bits()])
                .collect();
            if l.is_closed() {
                points.pop();
                points = (0..points.len())
                    .map(|m| {
                        let mut rotation = points.clone();
                        rotation.rotate_left(m);
                        rotation
                    })
                    .min()
                    .unwrap_or_default();
            }
            (l.level().to_bits(), l.is_closed(), points)
        })
        .collect();
    out.sort();
    out
}

proptest! {
    #[test]
    fn lines_do_not_depend_on_vertex_numbering(
        spec in small_grid(),
        e in max_error(),
        seed in any::<u64>(),
    ) {
        // Integer heights and levels at sample values: rings touching the level at a
        // vertex or along an edge, whose excursions must go wherever the ring starts.
        let spec = GridSpec {
            values: spec.values.iter().map(|v| (v * 4.0).round()).collect(),
            ..spec
        };
        let levels = levels_for(&spec, seed);
        for mesh in meshes(&spec, e) {
            let n = mesh.vertices().len();
            let mut order: Vec<u32> = (0..n as u32).collect();
            let mut rng = SplitMix::new(seed);
            for i in (1..n).rev() {
                order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            let mut vertices = vec![[0.0; 3]; n];
            for (old, &new) in order.iter().enumerate() {
                vertices[new as usize] = mesh.vertices()[old];
            }
            let triangles = mesh
                .triangles()
                .iter()
                .map(|t| t.map(|v| order[v as usize]))
                .collect();
            let relabelled = ContourMesh::new(vertices, triangles).unwrap();
            prop_assert_eq!(
                canonical(&contour(&mesh, &levels).unwrap()),
                canonical(&contour(&relabelled, &levels).unwrap())
            );
        }
    }
}
