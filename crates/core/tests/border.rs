//! Tiles that share a border: decimated separately with the same kept border samples, they
//! weld into one valid TIN of the whole grid within the bound.

use tinsmith_core::{
    decimate_with_border, effective_limit, DecimationOptions, ErrorModel, Grid, InitialMesh, Tin,
};
use tinsmith_testkit::{terrain, with_nodata_disc, GridSpec};
use tinsmith_verify::{verify, GridRef, MeshRef, VerifyOptions};

/// Greedy 1-D simplification of the column `x` of `spec` (written for this test, not
/// shared with any engine): keep the ends, every sample next to an invalid cell on either
/// side, and otherwise the farthest sample the straight line can reach within `limit`.
fn kept_rows(spec: &GridSpec, x: u32, limit: f64) -> Vec<bool> {
    let (w, h) = (spec.width, spec.height);
    let v = |x: u32, y: u32| spec.values[(y * w + x) as usize];
    let cell_ok = |cx: i64, y: u32| {
        cx >= 0
            && (cx as u32) < w - 1
            && [
                v(cx as u32, y),
                v(cx as u32 + 1, y),
                v(cx as u32, y + 1),
                v(cx as u32 + 1, y + 1),
            ]
            .iter()
            .all(|z| z.is_finite())
    };
    // Segment (y, y + 1) of the column can be skipped over when both strip cells are valid.
    let open = |y: u32| cell_ok(x as i64 - 1, y) && cell_ok(x as i64, y);
    let mut keep = vec![false; h as usize];
    keep[0] = true;
    keep[h as usize - 1] = true;
    for y in 0..h - 1 {
        if !open(y) {
            keep[y as usize] = true;
            keep[y as usize + 1] = true;
        }
    }
    let mut a = 0u32;
    while a < h - 1 {
        let mut b = a + 1;
        while b < h - 1 && !keep[b as usize] {
            let c = b + 1;
            let fits = (a + 1..c).all(|m| {
                let t = (m - a) as f64 / (c - a) as f64;
                (v(x, m) - (v(x, a) + t * (v(x, c) - v(x, a)))).abs() <= limit
            });
            if !fits {
                break;
            }
            b = c;
        }
        keep[b as usize] = true;
        a = b;
    }
    keep
}

fn window(spec: &GridSpec, x0: u32, x1: u32) -> GridSpec {
    let w = x1 - x0 + 1;
    let values = (0..spec.height)
        .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
        .map(|(x, y)| spec.values[(y * spec.width + x) as usize])
        .collect();
    GridSpec {
        width: w,
        height: spec.height,
        values,
    }
}

fn check_two_tiles(spec: &GridSpec, bound: f64, model: ErrorModel, initial: InitialMesh) {
    let split = spec.width / 2;
    let max_abs = spec
        .values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let limit = effective_limit(bound, max_abs);
    let shared = kept_rows(spec, split, limit);
    let options = DecimationOptions {
        max_abs_value: Some(max_abs),
        initial_mesh: initial,
        ..DecimationOptions::new(bound).with_error_model(model)
    };
    let mut welded: Vec<([i64; 2], f64)> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for (x0, x1) in [(0, split), (split, spec.width - 1)] {
        let tile = window(spec, x0, x1);
        let grid = Grid::new(tile.width, tile.height, tile.values.clone()).unwrap();
        let tw = tile.width;
        // Outer sides of the whole grid are simplified by their own column/row rules; here
        // only the shared column matters, so the other sides keep every sample.
        let keep = |x: u32, y: u32| {
            let global_x = x0 + x;
            if global_x == split && (x == 0 || x == tw - 1) {
                shared[y as usize]
            } else {
                true
            }
        };
        let tin: Tin = decimate_with_border(&grid, &options, &keep, &mut |_| {})
            .unwrap()
            .tin;
        // The shared column holds exactly the kept samples.
        let col = if x0 == 0 { tw - 1 } else { 0 };
        let on_col: Vec<u32> = tin
            .vertices()
            .iter()
            .filter(|v| v.x == col)
            .map(|v| v.y)
            .collect();
        let expected: Vec<u32> = (0..spec.height)
            .filter(|&y| shared[y as usize] && tile.values[(y * tw + col) as usize].is_finite())
            .collect();
        let mut on_col_sorted = on_col.clone();
        on_col_sorted.sort();
        if tile.values.iter().all(|v| v.is_finite()) {
            assert_eq!(on_col_sorted, expected, "shared column vertices");
        }
        // Kept samples not on any valid cell are not vertices.
        assert!(
            on_col_sorted.iter().all(|y| expected.contains(y)),
            "{on_col_sorted:?} vs {expected:?}"
        );
        // Weld by global position.
        let mut map = Vec::new();
        for v in tin.vertices() {
            let p = [(x0 + v.x) as i64, v.y as i64];
            match welded.iter().position(|(q, _)| *q == p) {
                Some(i) => map.push(i as u32),
                None => {
                    map.push(welded.len() as u32);
                    welded.push((p, v.z));
                }
            }
        }
        triangles.extend(tin.triangles().iter().map(|t| t.map(|i| map[i as usize])));
    }
    let positions: Vec<[i64; 2]> = welded.iter().map(|w| w.0).collect();
    let heights: Vec<f64> = welded.iter().map(|w| w.1).collect();
    let report = verify(
        GridRef::new(spec.width, spec.height, &spec.values),
        MeshRef::new(&positions, &heights, &triangles),
        &VerifyOptions::new().with_max_error(bound),
    )
    .unwrap();
    assert!(report.passed(), "{:?}", report.problems);
    // Crack-free: every edge is used by one or two triangles, and by two unless it is on
    // the domain's outline (checked through coverage and area by the verifier); here also
    // check no edge is used three times and the shared column has no dangling edge.
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort();
    for run in edges.chunk_by(|a, b| a == b) {
        assert!(run.len() <= 2);
        if run.len() == 1 {
            let (a, b) = run[0];
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            let interior_of_split = pa[0] == split as i64
                && pb[0] == split as i64
                && pa[1] > 0
                && pb[1] > 0
                && pa[1] < spec.height as i64 - 1;
            assert!(
                !interior_of_split || spec.values.iter().any(|v| !v.is_finite()),
                "crack along the shared column at {pa:?}-{pb:?}"
            );
        }
    }
}

#[test]
fn two_tiles_weld_within_the_bound() {
    for model in [ErrorModel::Bounds, ErrorModel::Exact] {
        for initial in [
            InitialMesh::Full,
            InitialMesh::Rtin,
            InitialMesh::Strips,
            InitialMesh::Insert,
            InitialMesh::Auto,
        ] {
            for bound in [0.5, 3.0, 20.0] {
                check_two_tiles(&terrain(41, 30, 3.0, 5), bound, model, initial);
                // Odd and even sizes put the RTIN's corner cells both ways.
                check_two_tiles(&terrain(38, 27, 3.0, 6), bound, model, initial);
            }
        }
    }
}

#[test]
fn nodata_across_the_shared_border() {
    let spec = with_nodata_disc(terrain(40, 36, 2.0, 9), 20.0, 18.0, 5.0);
    for model in [ErrorModel::Bounds, ErrorModel::Exact] {
        for initial in [
            InitialMesh::Full,
            InitialMesh::Rtin,
            InitialMesh::Strips,
            InitialMesh::Insert,
            InitialMesh::Auto,
        ] {
            check_two_tiles(&spec, 2.0, model, initial);
        }
    }
}

#[test]
fn narrow_tiles() {
    for w in [3, 4, 5] {
        for initial in [
            InitialMesh::Full,
            InitialMesh::Rtin,
            InitialMesh::Strips,
            InitialMesh::Insert,
            InitialMesh::Auto,
        ] {
            check_two_tiles(
                &terrain(w, 12, 5.0, w as u64),
                1.0,
                ErrorModel::Exact,
                initial,
            );
        }
    }
}

#[test]
fn whole_borders_skipped_on_a_plane() {
    // Every border sample but the corners is skipped: the fans along the border keep this
    // linear, and the plane decimates to two triangles.
    let n = 120u32;
    let values: Vec<f64> = (0..n * n)
        .map(|i| 0.5 * (i % n) as f64 - 0.25 * (i / n) as f64)
        .collect();
    let grid = Grid::new(n, n, values.clone()).unwrap();
    let options = DecimationOptions::new(0.01);
    let tin = decimate_with_border(&grid, &options, &|_, _| false, &mut |_| {})
        .unwrap()
        .tin;
    assert_eq!(tin.triangles().len(), 2);
    assert_within(n, n, &values, &tin, 0.01);
}

#[test]
fn a_long_two_row_grid_is_all_border() {
    // Every sample is on the border; the fans along both rows replace one another as the
    // runs grow, and only the last are measured (each measurement of a run's fan scans the
    // whole run), so this stays linear in the length.
    let (w, h) = (30_000u32, 2u32);
    let values: Vec<f64> = (0..w * h)
        .map(|i| 0.125 * (i % w) as f64 + 3.0 * (i / w) as f64)
        .collect();
    let grid = Grid::new(w, h, values.clone()).unwrap();
    let tin = decimate_with_border(
        &grid,
        &DecimationOptions::new(0.5),
        &|_, _| false,
        &mut |_| {},
    )
    .unwrap()
    .tin;
    assert_eq!(tin.triangles().len(), 2);
    assert_within(w, h, &values, &tin, 0.5);
}

/// Asserts that the independent verifier passes `tin` on the `w` x `h` grid `values` at
/// `max_error`.
fn assert_within(w: u32, h: u32, values: &[f64], tin: &Tin, max_error: f64) {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [v.x as i64, v.y as i64])
        .collect();
    let heights: Vec<f64> = tin.vertices().iter().map(|v| v.z).collect();
    let report = verify(
        GridRef::new(w, h, values),
        MeshRef::new(&positions, &heights, tin.triangles()),
        &VerifyOptions::new().with_max_error(max_error),
    )
    .unwrap();
    assert!(report.passed(), "{:?}", report.problems);
}

#[test]
fn a_skipped_sample_that_breaks_the_bound_is_an_error() {
    let mut spec = terrain(20, 20, 0.0, 3);
    spec.values[10] += 50.0; // a spike on the top border
    let grid = Grid::new(spec.width, spec.height, spec.values.clone()).unwrap();
    let err = decimate_with_border(
        &grid,
        &DecimationOptions::new(1.0),
        &|_, _| false,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(err.to_string().contains("border sample ("), "{err}");
    assert!(err.to_string().contains("error bound"), "{err}");

    // On a plane the spike is the only sample off the border edges, and it is named.
    let (w, h) = (20u32, 20u32);
    let mut values: Vec<f64> = (0..w * h).map(|i| 0.5 * (i % w) as f64).collect();
    values[(h - 1) as usize * w as usize + 13] += 5.0;
    let grid = Grid::new(w, h, values).unwrap();
    let options = DecimationOptions::new(1.0);
    let err = decimate_with_border(&grid, &options, &|_, _| false, &mut |_| {}).unwrap_err();
    assert!(err.to_string().contains("border sample (13, 19)"), "{err}");
}

#[test]
fn insertion_starts_from_the_decided_border_on_seeded_terrain() {
    for (seed, bound) in [(11, 0.5), (12, 4.0), (13, 30.0)] {
        for initial in [InitialMesh::Insert, InitialMesh::Auto] {
            check_two_tiles(
                &terrain(65, 48, 4.0, seed),
                bound,
                ErrorModel::Exact,
                initial,
            );
        }
    }
}

#[test]
fn insertion_from_a_skipped_border_keeps_a_plane_at_two_triangles() {
    let n = 120u32;
    let values: Vec<f64> = (0..n * n)
        .map(|i| 0.5 * (i % n) as f64 - 0.25 * (i / n) as f64)
        .collect();
    let grid = Grid::new(n, n, values.clone()).unwrap();
    let options = DecimationOptions::new(0.01).with_initial_mesh(InitialMesh::Insert);
    let tin = decimate_with_border(&grid, &options, &|_, _| false, &mut |_| {})
        .unwrap()
        .tin;
    assert_eq!(tin.triangles().len(), 2);
    assert_within(n, n, &values, &tin, 0.01);
}
