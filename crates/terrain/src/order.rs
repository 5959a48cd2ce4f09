//! The order a tile's triangles are written in, and each triangle's first corner: chosen
//! so that the encoders, which number vertices by first use, see small index codes and
//! position deltas, which gzip packs tightly. Order only: the same triangles, each with
//! its winding, whatever the order.

use std::collections::HashMap;

/// The triangles in the order the tile encoders write them:
///
/// 1. along a Hilbert curve through their centroids (neighbours in space one after
///    another);
/// 2. then walked across shared edges: after each triangle comes its unwritten neighbour
///    earliest on the curve, or, when it has none, the next unwritten triangle on the
///    curve (so most triangles reuse two vertices of the one before);
/// 3. each triangle's corners rotated (its winding kept) so that the corner first used
///    earliest leads, and a vertex used for the first time comes last: the
///    high-water-mark codes repeat in few patterns.
///
/// Decided by positions and connectivity alone: the same mesh gives the same order.
pub(super) fn encoding_order(vertices: &[[u16; 3]], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let curve = in_space_order(vertices, triangles);
    rotate_corners(&walk_across_edges(&curve))
}

/// The triangles along a Hilbert curve through their centroids.
fn in_space_order(vertices: &[[u16; 3]], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let key = |t: &[u32; 3]| {
        let (x, y) = t.iter().fold((0u32, 0u32), |(x, y), &v| {
            let p = vertices[v as usize];
            (x + u32::from(p[0]), y + u32::from(p[1]))
        });
        hilbert(x / 3, y / 3)
    };
    let mut ordered: Vec<(u64, [u32; 3])> = triangles.iter().map(|t| (key(t), *t)).collect();
    ordered.sort_unstable();
    ordered.into_iter().map(|(_, t)| t).collect()
}

/// `triangles` (in curve order) re-ordered by walking to the unwritten edge neighbour
/// earliest in that order, restarting at the earliest unwritten triangle.
fn walk_across_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    // Each undirected edge's (up to two) triangles.
    let mut sides: HashMap<(u32, u32), [u32; 2]> = HashMap::with_capacity(triangles.len() * 2);
    for (k, t) in triangles.iter().enumerate() {
        for r in 0..3 {
            let (a, b) = (t[r], t[(r + 1) % 3]);
            let entry = sides.entry((a.min(b), a.max(b))).or_insert([u32::MAX; 2]);
            let slot = usize::from(entry[0] != u32::MAX);
            entry[slot] = k as u32;
        }
    }
    let mut written = vec![false; triangles.len()];
    let mut out = Vec::with_capacity(triangles.len());
    let mut next_on_curve = 0;
    let mut current: Option<usize> = None;
    while out.len() < triangles.len() {
        let k = match current {
            Some(k) => k,
            None => {
                while written[next_on_curve] {
                    next_on_curve += 1;
                }
                next_on_curve
            }
        };
        written[k] = true;
        let t = triangles[k];
        out.push(t);
        current = (0..3)
            .flat_map(|r| {
                let (a, b) = (t[r], t[(r + 1) % 3]);
                sides[&(a.min(b), a.max(b))]
            })
            .filter(|&n| n != u32::MAX && !written[n as usize])
            .min()
            .map(|n| n as usize);
    }
    out
}

/// Each triangle's corners rotated, winding kept, so that the sequence of the corners'
/// first-use ranks is smallest: the earliest-used corner leads, new vertices come last.
fn rotate_corners(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut rank: HashMap<u32, u32> = HashMap::with_capacity(triangles.len());
    triangles
        .iter()
        .map(|t| {
            let key = |i: u32| rank.get(&i).copied().unwrap_or(u32::MAX);
            let best = (0..3)
                .map(|r| [t[r], t[(r + 1) % 3], t[(r + 2) % 3]])
                .min_by_key(|c| c.map(key))
                .expect("three rotations");
            for &i in &best {
                let next = rank.len() as u32;
                rank.entry(i).or_insert(next);
            }
            best
        })
        .collect()
}

/// The position of (`x`, `y`) (16 bits each) along a Hilbert curve over the 2^16 square.
fn hilbert(x: u32, y: u32) -> u64 {
    let (mut x, mut y) = (x & 0xffff, y & 0xffff);
    let mut d = 0u64;
    let mut s = 1u32 << 15;
    while s > 0 {
        let rx = u32::from(x & s > 0);
        let ry = u32::from(y & s > 0);
        d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        // Rotate the quadrant so the curve continues.
        if ry == 0 {
            if rx == 1 {
                x = 0xffff - x;
                y = 0xffff - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s >>= 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same triangle up to the rotation of its corners (winding kept).
    fn canonical(t: [u32; 3]) -> [u32; 3] {
        (0..3)
            .map(|r| [t[r], t[(r + 1) % 3], t[(r + 2) % 3]])
            .min()
            .unwrap()
    }

    #[test]
    fn the_order_keeps_every_triangle_and_its_winding() {
        // A 4 x 4 grid of quads, two triangles each.
        let n = 5u32;
        let vertices: Vec<[u16; 3]> = (0..n * n)
            .map(|k| {
                [
                    (k % n * 8000) as u16,
                    (k / n * 8000) as u16,
                    (k * 7 % 13) as u16,
                ]
            })
            .collect();
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                triangles.push([a, a + 1, a + n + 1]);
                triangles.push([a, a + n + 1, a + n]);
            }
        }
        let ordered = encoding_order(&vertices, &triangles);
        let mut got: Vec<_> = ordered.iter().map(|&t| canonical(t)).collect();
        let mut want: Vec<_> = triangles.iter().map(|&t| canonical(t)).collect();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want);
        // Each triangle after the first shares an edge with the one before (the grid is
        // one connected strip for the walk) or starts a new run; most share one.
        let shared = ordered
            .windows(2)
            .filter(|w| w[1].iter().filter(|v| w[0].contains(v)).count() == 2)
            .count();
        assert!(
            shared * 10 >= (ordered.len() - 1) * 8,
            "{shared} of {}",
            ordered.len() - 1
        );
        // New vertices come last in their triangle: the first corner of every triangle
        // after the first is a vertex already used.
        let mut seen = std::collections::HashSet::new();
        for (k, t) in ordered.iter().enumerate() {
            if k > 0 && t.iter().any(|v| seen.contains(v)) {
                assert!(seen.contains(&t[0]), "triangle {k}: {t:?}");
            }
            seen.extend(t.iter().copied());
        }
    }
}
