//! Douglas–Peucker simplification of a line within a distance: an opt-in step after
//! contouring that gives up the lines' exactness on the TIN for fewer points.

/// The indices of the points of `points` that Douglas–Peucker keeps within `tolerance`,
/// in order.
///
/// This is not part of contouring: the points of a [`crate::Polyline`] are exact contour
/// points of the TIN, and a simplified line is not. What it promises instead is a distance
/// in the plane of the points (whatever coordinates they are in).
///
/// # Guarantees
/// - The kept points are a subsequence of `points`, first and last included. Every dropped
///   point is within `tolerance` (Euclidean) of the segment between the kept points around
///   it, so every point of the original line is within `tolerance` of the simplified line
///   and every point of the simplified line is within `tolerance` of the original (their
///   Hausdorff distance is at most `tolerance`).
/// - A closed line (at least 4 points, first == last) stays closed with at least 3
///   distinct points: it is split at the point farthest from its start and each half is
///   simplified; if that keeps only the start and the split point, the point farthest
///   from the chord between them is kept too and its half simplified again on both sides
///   of it.
/// - No two consecutive kept points are equal. If the kept points would not make a valid
///   line (fewer than 2 points, or fewer than 4 for a closed line: possible only when the
///   line revisits a point), every index is returned.
/// - Not guaranteed: two lines simplified separately may come closer than before, by up to
///   twice `tolerance`, so lines closer than that (adjacent levels on steep ground, or a
///   line and itself) can touch or cross after simplification.
/// - `tolerance <= 0` or NaN, or at most 2 points: every index, the line unchanged.
///
/// # Runtime
/// `O(n log n)` for typical lines, `O(n²)` in the worst case; iterative, no recursion.
///
/// # Example
/// ```
/// use tinsmith_contour::simplify_indices;
/// let line = [[0.0, 0.0], [1.0, 0.1], [2.0, -0.1], [3.0, 5.0], [4.0, 6.0]];
/// assert_eq!(simplify_indices(&line, 0.5), vec![0, 2, 3, 4]);
/// ```
pub fn simplify_indices(points: &[[f64; 2]], tolerance: f64) -> Vec<usize> {
    let n = points.len();
    let all = || (0..n).collect();
    if tolerance.is_nan() || tolerance <= 0.0 || n <= 2 {
        return all();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let closed = n >= 4 && points[0] == points[n - 1];
    if closed {
        let start = points[0];
        let far = farthest(points, 1, n - 1, |p| distance(p, start));
        keep[far] = true;
        douglas_peucker(points, 0, far, tolerance, &mut keep);
        douglas_peucker(points, far, n - 1, tolerance, &mut keep);
        if keep.iter().filter(|&&k| k).count() == 3 {
            // Only the start, `far` and the end: keep the point farthest from the chord
            // between them as well, and simplify its half again on both sides of it.
            let (pa, pb) = (start, points[far]);
            let from_chord = |p| segment_distance(p, pa, pb);
            let before = (far > 1).then(|| farthest(points, 1, far, from_chord));
            let after = (far + 1 < n - 1).then(|| farthest(points, far + 1, n - 1, from_chord));
            let (a, third, b) = match (before, after) {
                (Some(i), Some(j)) if from_chord(points[j]) > from_chord(points[i]) => {
                    (far, j, n - 1)
                }
                (Some(i), _) => (0, i, far),
                (None, Some(j)) => (far, j, n - 1),
                // Impossible: 1..n-1 holds at least 2 indices, `far` only one of them.
                (None, None) => return all(),
            };
            keep[third] = true;
            douglas_peucker(points, a, third, tolerance, &mut keep);
            douglas_peucker(points, third, b, tolerance, &mut keep);
        }
    } else {
        douglas_peucker(points, 0, n - 1, tolerance, &mut keep);
    }
    let mut kept: Vec<usize> = (0..n).filter(|&i| keep[i]).collect();
    kept.dedup_by(|later, earlier| points[*later] == points[*earlier]);
    let valid = kept.len() >= if closed { 4 } else { 2 };
    if valid {
        kept
    } else {
        all()
    }
}

/// Marks in `keep` the points of `points[first..=last]` Douglas–Peucker keeps between the
/// kept ends `first` and `last`.
fn douglas_peucker(
    points: &[[f64; 2]],
    first: usize,
    last: usize,
    tolerance: f64,
    keep: &mut [bool],
) {
    let mut stack = vec![(first, last)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (pa, pb) = (points[a], points[b]);
        let at = farthest(points, a + 1, b, |p| segment_distance(p, pa, pb));
        if segment_distance(points[at], pa, pb) > tolerance {
            keep[at] = true;
            stack.push((a, at));
            stack.push((at, b));
        }
    }
}

/// The index in `from..to` (not empty) whose point has the largest `key`; the first on
/// ties.
fn farthest(points: &[[f64; 2]], from: usize, to: usize, key: impl Fn([f64; 2]) -> f64) -> usize {
    let mut best = (from, key(points[from]));
    for (i, &p) in points.iter().enumerate().take(to).skip(from + 1) {
        let d = key(p);
        if d > best.1 {
            best = (i, d);
        }
    }
    best.0
}

fn distance(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// Distance from `p` to the closed segment `a`–`b` (to `a` when `a == b`).
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let v = [p[0] - a[0], p[1] - a[1]];
    let dd = d[0] * d[0] + d[1] * d[1];
    let t = if dd > 0.0 {
        ((v[0] * d[0] + v[1] * d[1]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (v[0] - t * d[0]).hypot(v[1] - t * d[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_to_do() {
        let line = [[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]];
        for tolerance in [0.0, -1.0, f64::NAN] {
            assert_eq!(simplify_indices(&line, tolerance), vec![0, 1, 2]);
        }
        assert_eq!(simplify_indices(&line[..2], 10.0), vec![0, 1]);
        assert_eq!(simplify_indices(&[], 1.0), Vec::<usize>::new());
    }

    #[test]
    fn straight_runs_collapse_and_corners_stay() {
        let line = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [2.0, 2.0]];
        assert_eq!(simplify_indices(&line, 0.01), vec![0, 2, 4]);
        // The corner is 1.41 from the chord: dropped at a larger tolerance.
        assert_eq!(simplify_indices(&line, 1.5), vec![0, 4]);
    }

    #[test]
    fn dropped_points_stay_within_the_tolerance() {
        // A noisy sine: check the guarantee point by point.
        let line: Vec<[f64; 2]> = (0..200)
            .map(|i| {
                let x = i as f64 * 0.1;
                [x, x.sin() + 0.05 * ((i * 7919 % 13) as f64 - 6.0) / 6.0]
            })
            .collect();
        for tolerance in [0.01, 0.1, 0.3] {
            let kept = simplify_indices(&line, tolerance);
            assert!(kept.len() < line.len());
            assert_eq!((kept[0], *kept.last().unwrap()), (0, 199));
            for w in kept.windows(2) {
                for p in &line[w[0]..=w[1]] {
                    let d = segment_distance(*p, line[w[0]], line[w[1]]);
                    assert!(d <= tolerance, "{d} > {tolerance}");
                }
            }
        }
    }

    #[test]
    fn rings_stay_rings() {
        // A small square ring, simplified with a tolerance larger than itself.
        let ring = [
            [0.0, 0.0],
            [0.5, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.0, 0.0],
        ];
        let kept = simplify_indices(&ring, 10.0);
        assert_eq!(kept.first(), Some(&0));
        assert_eq!(kept.last(), Some(&5));
        assert_eq!(kept.len(), 4, "{kept:?}");
        // Within a small tolerance only the collinear midpoint goes.
        assert_eq!(simplify_indices(&ring, 0.01), vec![0, 2, 3, 4, 5]);
    }

    proptest::proptest! {
        /// Random walks, open or closed: the kept indices are an increasing subsequence
        /// with both ends, every dropped point is within the tolerance of its segment, no
        /// segment has zero length, and rings keep 3 distinct points.
        #[test]
        fn guarantees_hold_on_random_lines(
            steps in proptest::collection::vec((-3i8..=3, -3i8..=3), 1..60),
            closed in proptest::bool::ANY,
            tolerance in 0.1f64..4.0,
        ) {
            let mut line = vec![[0.0, 0.0]];
            for (dx, dy) in steps {
                let [x, y] = line[line.len() - 1];
                let next = [x + f64::from(dx), y + f64::from(dy)];
                if next != [x, y] {
                    line.push(next);
                }
            }
            if closed && line.len() >= 3 && line[line.len() - 1] != line[0] {
                line.push(line[0]);
            }
            let kept = simplify_indices(&line, tolerance);
            let n = line.len();
            proptest::prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
            proptest::prop_assert_eq!((kept[0], kept[kept.len() - 1]), (0, n - 1));
            if kept.len() < n {
                for w in kept.windows(2) {
                    proptest::prop_assert!(line[w[0]] != line[w[1]]);
                    for p in &line[w[0]..=w[1]] {
                        proptest::prop_assert!(segment_distance(*p, line[w[0]], line[w[1]]) <= tolerance);
                    }
                }
                if n >= 4 && line[0] == line[n - 1] {
                    proptest::prop_assert!(kept.len() >= 4);
                }
            }
        }
    }

    #[test]
    fn revisited_points_do_not_make_zero_length_segments() {
        // The line comes back to (1, 0) after a short detour.
        let line = [[0.0, 0.0], [1.0, 0.0], [1.1, 0.05], [1.0, 0.0], [3.0, 0.0]];
        let kept = simplify_indices(&line, 0.2);
        for w in kept.windows(2) {
            assert_ne!(line[w[0]], line[w[1]]);
        }
        assert_eq!(kept, vec![0, 4]);
    }
}
