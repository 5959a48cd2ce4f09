//! Exact scan conversion of a triangle over the integer samples of a grid.

use crate::predicates::orient;

/// Calls `visit(x, y, weights)` once for every sample `(x, y)` of a `width x height` grid
/// that lies in the closed triangle `tri`, in row-major order.
///
/// `weights = s * [orient(b, c, p), orient(c, a, p), orient(a, b, p)]` with
/// `s = sign(orient(a, b, c))`: all `>= 0`, summing to `|orient(a, b, c)|`. Degenerate
/// triangles (`orient == 0`) visit nothing. Either winding is accepted.
///
/// # Panics
/// If `|orient(a, b, c)|` or a coordinate difference exceeds `i64::MAX / 2`. A triangle
/// with its corners inside a grid held in memory cannot: its doubled area is at most
/// `(width - 1) * (height - 1)`, below the number of samples.
///
/// # Runtime
/// Each row's span is computed exactly from the three edges, so the work is linear in the
/// number of rows plus the number of samples visited. Each visited sample is still
/// confirmed by the three exact weights, so the spans only bound the scan.
pub(crate) fn rasterize(
    tri: [[i64; 2]; 3],
    width: u32,
    height: u32,
    visit: impl FnMut(u32, u32, [i64; 3]),
) {
    rasterize_rows(tri, width, height, |_| true, visit);
}

/// [`rasterize`] over the rows `keep_row` accepts only: the others cost one call each.
pub(crate) fn rasterize_rows(
    tri: [[i64; 2]; 3],
    width: u32,
    height: u32,
    keep_row: impl Fn(u32) -> bool,
    mut visit: impl FnMut(u32, u32, [i64; 3]),
) {
    let area_x2 = orient(tri[0], tri[1], tri[2]);
    let sign = area_x2.signum();
    if sign == 0 || width == 0 || height == 0 {
        return;
    }
    let half = i128::from(i64::MAX / 2);
    let fits = |v: i128| -half <= v && v <= half;
    let xs = tri.map(|p| i128::from(p[0]));
    let ys = tri.map(|p| i128::from(p[1]));
    let x_min = xs.iter().copied().min().unwrap_or(0).max(0);
    let x_max = xs
        .iter()
        .copied()
        .max()
        .unwrap_or(0)
        .min(i128::from(width) - 1);
    let y_min = ys.iter().copied().min().unwrap_or(0).max(0);
    let y_max = ys
        .iter()
        .copied()
        .max()
        .unwrap_or(0)
        .min(i128::from(height) - 1);
    if x_min > x_max {
        return;
    }
    // Edge i is opposite vertex i; its weight at (x, y) is `slope[i] * x + offset(y)`.
    let edges: [([i128; 2], [i128; 2]); 3] = [0, 1, 2].map(|i| {
        let (p, q) = ((i + 1) % 3, (i + 2) % 3);
        ([xs[p], ys[p]], [xs[q], ys[q]])
    });
    let slopes = edges.map(|(p, q)| -sign * (q[1] - p[1]));
    assert!(
        fits(area_x2)
            && edges
                .iter()
                .all(|(p, q)| fits(q[0] - p[0]) && fits(q[1] - p[1])),
        "triangle {tri:?} too large for 64-bit weights"
    );
    // Inside, weights lie in 0..=|area_x2|, so with one slope added they stay in i64.
    let narrow = |v: i128| i64::try_from(v).expect("weights and slopes are checked to fit");
    let steps = slopes.map(narrow);
    for y in y_min..=y_max {
        // In range: y lies within the grid, whose sides fit in u32.
        if !keep_row(y as u32) {
            continue;
        }
        let offsets =
            edges.map(|(p, q)| sign * ((q[0] - p[0]) * (y - p[1]) + (q[1] - p[1]) * p[0]));
        let (mut lo, mut hi) = (x_min, x_max);
        for (&slope, &offset) in slopes.iter().zip(&offsets) {
            match slope.signum() {
                // slope * x + offset >= 0  <=>  x >= ceil(-offset / slope)
                1 => lo = lo.max(-floor_div(offset, slope)),
                // <=>  x <= floor(offset / -slope)
                -1 => hi = hi.min(floor_div(offset, -slope)),
                _ if offset < 0 => hi = lo - 1,
                _ => {}
            }
        }
        if lo > hi {
            continue;
        }
        // The span is exact, so lo is inside: its weights are in 0..=|area_x2|.
        let mut weights = [0, 1, 2].map(|i| narrow(slopes[i] * lo + offsets[i]));
        // In range: lo..=hi and y lie within the grid, whose sides fit in u32.
        let row = y as u32;
        for x in lo..=hi {
            if weights.iter().all(|&w| w >= 0) {
                visit(x as u32, row, weights);
            }
            for (w, step) in weights.iter_mut().zip(steps) {
                *w += step;
            }
        }
    }
}

/// `floor(n / d)` for `d > 0`, in 64 bits when both fit (a grid's triangles always do;
/// 128-bit division is a library call several times slower), else in 128.
fn floor_div(n: i128, d: i128) -> i128 {
    match (i64::try_from(n), i64::try_from(d)) {
        (Ok(n), Ok(d)) => i128::from(n.div_euclid(d)),
        _ => n.div_euclid(d),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sample of the grid tested on its own: the reference the spans must match.
    fn brute_force(tri: [[i64; 2]; 3], width: u32, height: u32) -> Vec<(u32, u32, [i64; 3])> {
        let sign = orient(tri[0], tri[1], tri[2]).signum();
        let mut out = Vec::new();
        if sign == 0 {
            return out;
        }
        for y in 0..height {
            for x in 0..width {
                let p = [i64::from(x), i64::from(y)];
                let w = [
                    sign * orient(tri[1], tri[2], p),
                    sign * orient(tri[2], tri[0], p),
                    sign * orient(tri[0], tri[1], p),
                ];
                if w.iter().all(|&w| w >= 0) {
                    out.push((x, y, w.map(|w| i64::try_from(w).expect("small test"))));
                }
            }
        }
        out
    }

    fn scan(tri: [[i64; 2]; 3], width: u32, height: u32) -> Vec<(u32, u32, [i64; 3])> {
        let mut out = Vec::new();
        rasterize(tri, width, height, |x, y, w| out.push((x, y, w)));
        out
    }

    #[test]
    fn floor_div_matches_128_bit_division() {
        let big = i128::from(i64::MAX) * 4 + 3;
        for n in [-big, -7, -6, -1, 0, 1, 6, 7, big, i128::from(i64::MIN)] {
            for d in [1, 2, 3, 7, big] {
                assert_eq!(floor_div(n, d), n.div_euclid(d), "{n} / {d}");
            }
        }
    }

    #[test]
    fn unit_triangle_visits_its_corners() {
        let got = scan([[0, 0], [1, 0], [0, 1]], 2, 2);
        assert_eq!(
            got,
            vec![(0, 0, [1, 0, 0]), (1, 0, [0, 1, 0]), (0, 1, [0, 0, 1])]
        );
        // Same triangle, clockwise: same samples, same weights.
        let got = scan([[0, 0], [0, 1], [1, 0]], 2, 2);
        assert_eq!(
            got,
            vec![(0, 0, [1, 0, 0]), (1, 0, [0, 0, 1]), (0, 1, [0, 1, 0])]
        );
    }

    #[test]
    fn degenerate_visits_nothing() {
        assert!(scan([[0, 0], [1, 1], [3, 3]], 4, 4).is_empty());
        assert!(scan([[2, 2], [2, 2], [2, 2]], 4, 4).is_empty());
    }

    #[test]
    fn spans_match_brute_force_on_random_triangles() {
        // Deterministic LCG (Knuth's MMIX constants); vertices may lie outside the grid.
        let mut state: u64 = 0x5eed;
        let mut next = |n: i64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % n as u64) as i64 - 3
        };
        let (width, height) = (13, 11);
        let mut visited = 0;
        for _ in 0..2000 {
            let tri = [0; 3].map(|_| [next(19), next(17)]);
            let expected = brute_force(tri, width, height);
            assert_eq!(scan(tri, width, height), expected, "triangle {tri:?}");
            visited += expected.len();
        }
        assert!(visited > 10_000, "the test must exercise real triangles");
    }

    #[test]
    fn long_thin_triangle_matches_brute_force() {
        let tri = [[0, 0], [300, 1], [299, 1]];
        let got = scan(tri, 301, 2);
        assert_eq!(got, brute_force(tri, 301, 2));
        // Lattice points: (0,0), (299,1) and (300,1) only.
        assert_eq!(got.len(), 3);
    }

    #[test]
    fn largest_in_memory_triangle_is_exact() {
        // Half of a 2^31 x 2^31 grid (too big to allocate, but within the limit): the scan
        // is clipped to a small window and still exact there.
        let m = (1 << 31) - 1;
        let tri = [[0, 0], [m, 0], [0, m]];
        let got = scan(tri, 3, 2);
        assert_eq!(got, brute_force(tri, 3, 2));
        assert_eq!(got.len(), 6);
        assert_eq!(got[0], (0, 0, [m * m, 0, 0]));
    }

    #[test]
    #[should_panic(expected = "too large for 64-bit weights")]
    fn triangle_beyond_64_bit_weights_panics() {
        let m = i64::MAX / 2;
        scan([[0, 0], [m, 0], [0, m]], 2, 2);
    }
}
