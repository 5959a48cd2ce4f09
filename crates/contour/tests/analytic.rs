//! Contours of analytic grids at exactly known positions: a plane (straight lines), a cone
//! (rings of known radius), a saddle (the topology at the saddle point), plateaus and
//! peaks that sit exactly on a level.

use tinsmith_contour::{contour, ContourMesh, Polyline};
use tinsmith_core::{decimate, DecimationOptions, Grid};

fn grid(w: u32, h: u32, f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    (0..w * h)
        .map(|i| f((i % w) as f64, (i / w) as f64))
        .collect()
}

fn full(w: u32, h: u32, values: &[f64]) -> ContourMesh {
    ContourMesh::from_grid(w, h, values).unwrap()
}

fn decimated(w: u32, h: u32, values: &[f64], e: f64) -> ContourMesh {
    let g = Grid::new(w, h, values.to_vec()).unwrap();
    let tin = decimate(&g, &DecimationOptions::new(e)).unwrap().tin;
    let v = tin
        .vertices()
        .iter()
        .map(|v| [v.x as f64, v.y as f64, v.z])
        .collect();
    ContourMesh::new(v, tin.triangles().to_vec()).unwrap()
}

/// Twice the signed area (positive = counter-clockwise with y up).
fn signed_area(p: &[[f64; 2]]) -> f64 {
    p.windows(2)
        .map(|w| w[0][0] * w[1][1] - w[1][0] * w[0][1])
        .sum()
}

fn segments(lines: &[Polyline]) -> usize {
    lines.iter().map(Polyline::segment_count).sum()
}

#[test]
fn plane_gives_straight_lines_at_known_x() {
    let (w, h) = (12, 9);
    let v = grid(w, h, |x, y| 2.0 * x + 0.0 * y);
    let mesh = full(w, h, &v);
    // Between samples: x = 2.25 for level 4.5. At a sample column: x = 3 exactly.
    let lines = contour(&mesh, &[4.5, 6.0]).unwrap();
    assert_eq!(lines.len(), 2);
    for (line, x) in lines.iter().zip([2.25, 3.0]) {
        assert!(!line.is_closed());
        assert!(line.points().iter().all(|p| p[0] == x), "{line:?}");
        // High ground (+x) on the left: the line runs towards -y.
        assert_eq!(line.points().first().unwrap()[1], (h - 1) as f64);
        assert_eq!(line.points().last().unwrap()[1], 0.0);
        // Strictly monotone in y: no repeated point, no back-tracking.
        assert!(line.points().windows(2).all(|p| p[1][1] < p[0][1]));
    }
    // Through the sample column the merged line has exactly one point per row.
    assert_eq!(lines[1].points().len(), h as usize);
    // On the decimated plane (two triangles) each line has two segments: it crosses the
    // one interior edge.
    let mesh = decimated(w, h, &v, 0.01);
    assert_eq!(mesh.triangles().len(), 2);
    let lines = contour(&mesh, &[4.5, 6.0]).unwrap();
    assert_eq!(segments(&lines), 4);
    for (line, x) in lines.iter().zip([2.25, 3.0]) {
        assert!(line.points().iter().all(|p| (p[0] - x).abs() < 1e-12));
    }
}

#[test]
fn cone_gives_rings_at_known_radius() {
    let (n, c) = (41, 20.0);
    let dist = |x: f64, y: f64| (x - c).hypot(y - c);
    let v = grid(n, n, dist);
    let levels = [3.5, 7.25, 12.0, 18.5];
    let lines = contour(&full(n, n, &v), &levels).unwrap();
    assert_eq!(lines.len(), levels.len());
    for (line, &r) in lines.iter().zip(&levels) {
        assert_eq!(line.level(), r);
        assert!(line.is_closed());
        assert_eq!(line.points().first(), line.points().last());
        // Linear interpolation overestimates a convex function, so the TIN reaches r a
        // little inside the true circle: by at most L^2 / 8 * (1 / (r - 1)) on an edge of
        // length L <= sqrt(2).
        let tol = 0.25 / (r - 1.0);
        for p in line.points() {
            let d = dist(p[0], p[1]);
            assert!(d <= r + 1e-12 && d >= r - tol, "r {r}: point at {d}");
        }
        // The high ground is outside: on the left, the ring runs clockwise (y up).
        assert!(signed_area(line.points()) < 0.0);
        let area = -signed_area(line.points()) / 2.0;
        let circle = std::f64::consts::PI * r * r;
        assert!(
            (area - circle).abs() / circle < 0.05,
            "r {r}: {area} vs {circle}"
        );
    }
    // Decimated within 0.05: still one ring per level, near the circle. (A cone decimates
    // into thin radial fans, so the rings do not get fewer segments here; real terrain
    // does, see docs/results.md.)
    let e = 0.05;
    let coarse = contour(&decimated(n, n, &v, e), &levels).unwrap();
    assert_eq!(coarse.len(), levels.len());
    for (line, &r) in coarse.iter().zip(&levels) {
        assert!(line.is_closed());
        for p in line.points() {
            let d = dist(p[0], p[1]);
            assert!((d - r).abs() <= 0.5, "r {r}: point at {d}");
        }
    }
}

#[test]
fn peak_rings_run_counter_clockwise() {
    let (n, c) = (21, 10.0);
    let v = grid(n, n, |x, y| 100.0 - (x - c).hypot(y - c));
    let lines = contour(&full(n, n, &v), &[95.5]).unwrap();
    assert_eq!(lines.len(), 1);
    assert!(signed_area(lines[0].points()) > 0.0);
}

#[test]
fn saddle_topology() {
    // z = (x - c)^2 - (y - c)^2: zero exactly on both diagonals through the centre vertex.
    let (n, c) = (11, 5.0);
    let v = grid(n, n, |x, y| (x - c).powi(2) - (y - c).powi(2));
    let mesh = full(n, n, &v);
    // Level 0: the region below (the top and bottom wedges) is bounded by two open lines
    // along the diagonals, both through the saddle vertex, which is on the level.
    let lines = contour(&mesh, &[0.0]).unwrap();
    assert_eq!(lines.len(), 2, "{lines:?}");
    for line in &lines {
        assert!(!line.is_closed());
        assert!(line.points().contains(&[c, c]));
        // Every point is a diagonal vertex: |x - c| == |y - c|.
        for p in line.points() {
            assert_eq!((p[0] - c).abs(), (p[1] - c).abs(), "{line:?}");
        }
        // Along the x = y half the line follows the cells' split diagonals, vertex to
        // vertex (6 points); along the other half it also crosses each split diagonal at
        // its midpoint (5 vertices + 5 midpoints).
        assert_eq!(line.points().len(), 16);
    }
    // Off the saddle value: the two branches of a hyperbola, left and right for a positive
    // level, top and bottom for a negative one; none reaches the centre.
    for (level, axis) in [(2.5, 0), (-2.5, 1)] {
        let lines = contour(&mesh, &[level]).unwrap();
        assert_eq!(lines.len(), 2);
        let sides: Vec<bool> = lines
            .iter()
            .map(|l| {
                assert!(!l.is_closed());
                let s = l.points()[0][axis] < c;
                assert!(l.points().iter().all(|p| (p[axis] < c) == s));
                s
            })
            .collect();
        assert_ne!(sides[0], sides[1]);
    }
}

#[test]
fn plateau_at_the_level_is_outlined_along_its_edge() {
    // A 3 x 3 plateau at height 1 in a field of 0: the level-1 contour runs through the
    // plateau's 8 outer vertices, not inside it.
    let n = 9;
    let inside = |x: f64, y: f64| (3.0..=5.0).contains(&x) && (3.0..=5.0).contains(&y);
    let v = grid(n, n, |x, y| if inside(x, y) { 1.0 } else { 0.0 });
    let mesh = full(n, n, &v);
    let lines = contour(&mesh, &[1.0]).unwrap();
    assert_eq!(lines.len(), 1);
    let ring = &lines[0];
    assert!(ring.is_closed());
    assert_eq!(ring.points().len(), 9);
    for p in ring.points() {
        assert!(inside(p[0], p[1]) && !(p[0] == 4.0 && p[1] == 4.0), "{p:?}");
    }
    assert_eq!(signed_area(ring.points()), 2.0 * 4.0);
    // The minimum level has nothing below it: no line.
    assert!(contour(&mesh, &[0.0]).unwrap().is_empty());
    // Half way up: one ring between the plateau and the field.
    let half = contour(&mesh, &[0.5]).unwrap();
    assert_eq!(half.len(), 1);
    assert!(half[0].is_closed());
}

#[test]
fn a_ridge_that_only_touches_the_level_makes_no_line_and_no_spike() {
    let n = 9;
    // A ridge of three samples at 1 in a field of 0: the ground at or above the level is
    // the ridge itself, which encloses nothing, so there is no line (not a ring
    // A, B, C, B, A running out along the ridge and back).
    let ridge = |x: f64, y: f64| y == 4.0 && (3.0..=5.0).contains(&x);
    let v = grid(n, n, |x, y| if ridge(x, y) { 1.0 } else { 0.0 });
    assert!(contour(&full(n, n, &v), &[1.0]).unwrap().is_empty());
    // The same ridge on a hill that reaches the level elsewhere: the hill's line has no
    // excursion along the ridge (no point followed by another and then itself again).
    let v = grid(n, n, |x, y| {
        if ridge(x, y) {
            1.0
        } else if x >= 6.0 {
            2.0
        } else {
            0.0
        }
    });
    let lines = contour(&full(n, n, &v), &[1.0]).unwrap();
    assert!(!lines.is_empty());
    for line in &lines {
        let p = line.points();
        assert!(
            (2..p.len()).all(|i| p[i] != p[i - 2]),
            "back and forth in {p:?}"
        );
    }
}

#[test]
fn a_ridge_at_the_level_reaching_the_border_or_between_two_hills_is_not_drawn_twice() {
    let n = 9;
    // The ridge of the test above run out to the left border: it makes no line (it made
    // two, one along each side, the same segments in opposite directions).
    let to_border = |x: f64, y: f64| y == 4.0 && x <= 5.0;
    let v = grid(n, n, |x, y| if to_border(x, y) { 1.0 } else { 0.0 });
    assert!(contour(&full(n, n, &v), &[1.0]).unwrap().is_empty());
    // The same ridge joining a hill on the right to the left border, and a ridge joining
    // two hills: each hill keeps its own line, and no segment is drawn twice.
    for (ridge_from, left_hill) in [(0.0, false), (3.0, true)] {
        let v = grid(n, n, |x, y| {
            if x >= 6.0 || (left_hill && x <= 1.0) {
                2.0
            } else if y == 4.0 && x >= ridge_from {
                1.0
            } else {
                0.0
            }
        });
        let lines = contour(&full(n, n, &v), &[1.0]).unwrap();
        assert_eq!(lines.len(), if left_hill { 2 } else { 1 }, "{lines:?}");
        let mut segments = std::collections::HashSet::new();
        for line in &lines {
            for w in line.points().windows(2) {
                let key = |p: [f64; 2]| [p[0].to_bits(), p[1].to_bits()];
                let (a, b) = (key(w[0]), key(w[1]));
                assert!(segments.insert((a.min(b), a.max(b))), "{w:?} twice");
            }
            // Only the hills' outlines: no point on the ridge's inner samples.
            for p in line.points() {
                assert!(
                    !(p[1] == 4.0 && p[0] > ridge_from.max(2.0) && p[0] < 5.0),
                    "{p:?} on the ridge in {:?}",
                    line.points()
                );
            }
        }
    }
}

#[test]
fn a_vertex_that_only_touches_the_level_makes_no_line() {
    let n = 7;
    // A single peak at 1 in the middle, another on the border.
    let v = grid(n, n, |x, y| {
        if (x, y) == (3.0, 3.0) || (x, y) == (0.0, 3.0) {
            1.0
        } else {
            0.0
        }
    });
    let mesh = full(n, n, &v);
    assert!(contour(&mesh, &[1.0]).unwrap().is_empty());
    let lines = contour(&mesh, &[0.5]).unwrap();
    assert_eq!(lines.len(), 2);
    let open = lines.iter().filter(|l| !l.is_closed()).count();
    assert_eq!(
        open, 1,
        "the border peak gives an open line, the inner one a ring"
    );
}

#[test]
fn nodata_hole_ends_lines_and_order_is_by_level_then_edge() {
    let (w, h) = (10, 6);
    let mut v = grid(w, h, |x, _| x);
    for y in 2..4 {
        v[(y * w + 4) as usize] = f64::NAN;
    }
    let mesh = full(w, h, &v);
    let lines = contour(&mesh, &[6.5, 4.5, 2.5]).unwrap();
    let levels: Vec<f64> = lines.iter().map(Polyline::level).collect();
    // x = 4.5 crosses the hole's cells (x = 3..5, y = 1..4): two pieces.
    assert_eq!(levels, [2.5, 4.5, 4.5, 6.5]);
    assert!(lines[1].edges()[0] < lines[2].edges()[0]);
    for l in &lines {
        assert!(!l.is_closed());
        assert!(l.points().iter().all(|p| p[0] == l.level()));
    }
}
