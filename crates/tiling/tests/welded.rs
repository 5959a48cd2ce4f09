//! The tiled engine on grids in memory: the welded mesh passes the verifier on the whole
//! grid, is crack-free, does not depend on the thread count, and neighbouring tiles keep
//! identical shared edge vertices. Random grids of every awkward kind (testkit), tiles
//! down to 2x2 samples, grids that are not a multiple of the tile size, nodata across
//! tile edges.

use std::collections::HashMap;

use proptest::prelude::*;
use tinsmith_core::{DecimationOptions, ErrorModel, Grid};
use tinsmith_testkit::{max_error, small_grid, terrain, with_nodata_disc, GridSpec};
use tinsmith_tiling::{
    mesh_tiles, FinishedTile, GridSource, SinkError, TileIndex, TileOptions, TileSink, TilesReport,
};
use tinsmith_verify::{verify, GridRef, MeshRef, VerifyOptions};

/// The welded mesh rebuilt from the sink's view, plus each tile's vertices by position.
#[derive(Debug, Default, PartialEq)]
struct Welded {
    positions: Vec<[i64; 2]>,
    heights: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    tiles: Vec<(TileIndex, Vec<[u32; 2]>)>,
}

impl TileSink for Welded {
    fn tile(&mut self, tile: &FinishedTile) -> Result<(), SinkError> {
        assert_eq!(self.positions.len(), tile.first_new_id() as usize);
        let mut positions = Vec::new();
        for (i, v) in tile.vertices().iter().enumerate() {
            let p = [v.x as i64, v.y as i64];
            if tile.is_new(i) {
                assert_eq!(tile.ids()[i] as usize, self.positions.len(), "ids ascend");
                self.positions.push(p);
                self.heights.push(v.z);
            } else {
                let old = tile.ids()[i] as usize;
                assert_eq!(self.positions[old], p, "a shared id means the same sample");
                assert_eq!(self.heights[old].to_bits(), v.z.to_bits());
            }
            positions.push([v.x, v.y]);
        }
        let ids = tile.ids();
        self.triangles
            .extend(tile.triangles().iter().map(|t| t.map(|i| ids[i as usize])));
        self.tiles.push((tile.index(), positions));
        Ok(())
    }
}

fn grid_of(spec: &GridSpec) -> Grid {
    Grid::new(spec.width, spec.height, spec.values.clone()).expect("grid")
}

fn run(
    spec: &GridSpec,
    bound: f64,
    model: ErrorModel,
    size: u32,
    threads: usize,
) -> (Welded, TilesReport) {
    let grid = grid_of(spec);
    let options = TileOptions::new(DecimationOptions::new(bound).with_error_model(model))
        .with_tile_size(size)
        .with_threads(threads);
    let mut welded = Welded::default();
    let mut seen = Vec::new();
    let report = mesh_tiles(&GridSource::new(&grid), &options, &mut welded, &mut |p| {
        seen.push(p.done)
    })
    .expect("mesh_tiles");
    assert_eq!(
        seen,
        (1..=report.plan.len()).collect::<Vec<_>>(),
        "progress per tile"
    );
    (welded, report)
}

fn cell_is_valid(spec: &GridSpec, cx: i64, cy: i64) -> bool {
    let (w, h) = (spec.width as i64, spec.height as i64);
    if cx < 0 || cy < 0 || cx + 1 >= w || cy + 1 >= h {
        return false;
    }
    [(cx, cy), (cx + 1, cy), (cx, cy + 1), (cx + 1, cy + 1)]
        .iter()
        .all(|&(x, y)| spec.values[(y * w + x) as usize].is_finite())
}

/// Every edge is used by at most two triangles; an edge used once lies on the domain's
/// outline: axis-parallel, with only invalid cells (or the raster's outside) on the side
/// away from its triangle. Computed from the cells alone, not from the engine.
fn assert_crack_free(spec: &GridSpec, w: &Welded) {
    let mut uses: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for t in &w.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            uses.entry((a.min(b), a.max(b)))
                .or_default()
                .push(t[(k + 2) % 3]);
        }
    }
    for (&(a, b), thirds) in &uses {
        let (pa, pb) = (w.positions[a as usize], w.positions[b as usize]);
        assert!(
            thirds.len() <= 2,
            "edge {pa:?}-{pb:?} used {} times",
            thirds.len()
        );
        if thirds.len() == 2 {
            continue;
        }
        let pc = w.positions[thirds[0] as usize];
        assert!(
            pa[0] == pb[0] || pa[1] == pb[1],
            "edge {pa:?}-{pb:?} used once but not on a cell side: a crack"
        );
        // Steps along the edge, and the side of the line away from the triangle.
        if pa[1] == pb[1] {
            let away_above = pc[1] > pa[1];
            for x in pa[0].min(pb[0])..pa[0].max(pb[0]) {
                let cy = if away_above { pa[1] - 1 } else { pa[1] };
                assert!(
                    !cell_is_valid(spec, x, cy),
                    "edge {pa:?}-{pb:?} used once beside valid cell ({x}, {cy}): a crack"
                );
            }
        } else {
            let away_left = pc[0] > pa[0];
            for y in pa[1].min(pb[1])..pa[1].max(pb[1]) {
                let cx = if away_left { pa[0] - 1 } else { pa[0] };
                assert!(
                    !cell_is_valid(spec, cx, y),
                    "edge {pa:?}-{pb:?} used once beside valid cell ({cx}, {y}): a crack"
                );
            }
        }
    }
}

fn assert_bound_holds(spec: &GridSpec, bound: f64, w: &Welded, report: &TilesReport) {
    let check = verify(
        GridRef::new(spec.width, spec.height, &spec.values),
        MeshRef::new(&w.positions, &w.heights, &w.triangles),
        &VerifyOptions::new().with_max_error(bound),
    )
    .expect("verify");
    assert!(check.passed(), "{:?}", check.problems);
    assert_eq!(
        check.max_error, report.measured_max_error,
        "tiles measured the same"
    );
    assert_eq!(check.domain_samples, report.initial_vertices);
    assert_eq!(2 * check.valid_cells, report.initial_triangles);
    assert_eq!(w.positions.len() as u64, report.final_vertices);
    assert_eq!(w.triangles.len() as u64, report.final_triangles);
    let mut unique = w.positions.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), w.positions.len(), "each sample welded once");
}

/// Neighbouring tiles have the same vertices along their shared edge: a vertex of one
/// tile on the edge is a vertex of the other whenever the other has a valid cell (of its
/// own) at that sample.
fn assert_shared_edges_identical(spec: &GridSpec, w: &Welded, report: &TilesReport) {
    let plan = report.plan;
    let by_index: HashMap<TileIndex, &Vec<[u32; 2]>> =
        w.tiles.iter().map(|(i, v)| (*i, v)).collect();
    let check = |a: TileIndex, b: TileIndex, on_edge: &dyn Fn(&[u32; 2]) -> bool| {
        let bw = plan.window(b);
        let b_has_cell = |x: i64, y: i64| {
            [(x - 1, y - 1), (x, y - 1), (x - 1, y), (x, y)]
                .iter()
                .any(|&(cx, cy)| {
                    cx >= bw.x0 as i64
                        && cx < bw.x1() as i64
                        && cy >= bw.y0 as i64
                        && cy < bw.y1() as i64
                        && cell_is_valid(spec, cx, cy)
                })
        };
        let theirs: Vec<&[u32; 2]> = by_index[&b].iter().filter(|p| on_edge(p)).collect();
        for p in by_index[&a].iter().filter(|p| on_edge(p)) {
            if b_has_cell(p[0] as i64, p[1] as i64) {
                assert!(
                    theirs.contains(&p),
                    "{a} has {p:?} on the edge it shares with {b}"
                );
            }
        }
    };
    for index in plan.indices() {
        let t = plan.window(index);
        if index.col + 1 < plan.columns() {
            let right = TileIndex {
                col: index.col + 1,
                ..index
            };
            let on = |p: &[u32; 2]| p[0] == t.x1();
            check(index, right, &on);
            check(right, index, &on);
        }
        if index.row + 1 < plan.rows() {
            let below = TileIndex {
                row: index.row + 1,
                ..index
            };
            let on = |p: &[u32; 2]| p[1] == t.y1();
            check(index, below, &on);
            check(below, index, &on);
        }
    }
}

#[test]
fn terrain_with_many_tile_sizes_welds_within_the_bound() {
    let spec = terrain(41, 29, 3.0, 5);
    for model in [ErrorModel::Bounds, ErrorModel::Exact] {
        for size in [2, 3, 5, 8, 16, 41, 64] {
            for bound in [0.5, 3.0, 20.0] {
                let (w, report) = run(&spec, bound, model, size, 2);
                assert_bound_holds(&spec, bound, &w, &report);
                assert_crack_free(&spec, &w);
                assert_shared_edges_identical(&spec, &w, &report);
            }
        }
    }
}

#[test]
fn nodata_across_tile_edges() {
    // Discs of nodata centred on tile edges, corners and inside tiles.
    let mut spec = terrain(49, 37, 2.0, 9);
    for (cx, cy, r) in [
        (12.0, 10.0, 3.0),
        (24.0, 24.0, 4.5),
        (36.0, 5.0, 2.0),
        (7.0, 30.0, 1.0),
    ] {
        spec = with_nodata_disc(spec, cx, cy, r);
    }
    for size in [3, 7, 13, 25] {
        for model in [ErrorModel::Bounds, ErrorModel::Exact] {
            let (w, report) = run(&spec, 2.0, model, size, 2);
            assert_bound_holds(&spec, 2.0, &w, &report);
            assert_crack_free(&spec, &w);
            assert_shared_edges_identical(&spec, &w, &report);
        }
    }
}

#[test]
fn tiles_of_two_by_two_samples_keep_every_sample() {
    let spec = with_nodata_disc(terrain(9, 7, 5.0, 3), 4.0, 3.0, 1.0);
    let (w, report) = run(&spec, 1000.0, ErrorModel::Exact, 2, 2);
    assert_eq!(report.plan.len(), 8 * 6);
    assert_bound_holds(&spec, 1000.0, &w, &report);
    assert_crack_free(&spec, &w);
    // Every tile is one cell: nothing can go.
    assert_eq!(report.final_vertices, report.initial_vertices);
    assert_eq!(report.final_triangles, report.initial_triangles);
}

#[test]
fn a_plane_keeps_only_tile_corners() {
    let values = (0..31 * 22).map(|i| 0.25 * (i % 31) as f64 - 0.5 * (i / 31) as f64);
    let spec = GridSpec {
        width: 31,
        height: 22,
        values: values.collect(),
    };
    let (w, report) = run(&spec, 0.1, ErrorModel::Bounds, 11, 2);
    assert_bound_holds(&spec, 0.1, &w, &report);
    // 3 x 3 tiles (the last row of tiles is 2 samples high): 4 x 4 corners.
    assert_eq!(report.plan.len(), 9);
    assert_eq!(report.final_vertices, 16);
    assert_eq!(report.final_triangles, 18);
}

#[test]
fn a_bound_of_zero_keeps_every_edge_sample() {
    let spec = terrain(20, 20, 1.0, 2);
    let (w, report) = run(&spec, 0.0, ErrorModel::Bounds, 7, 2);
    assert_bound_holds(&spec, 0.0, &w, &report);
    assert_crack_free(&spec, &w);
}

#[test]
fn a_bound_of_zero_on_integer_heights_skips_exactly_collinear_edge_samples() {
    // Edges kept every sample at a bound of 0 (2130 triangles for a flat 180 x 180 raster
    // in tiles of 64, against 2 untiled); on integer heights the cores decide an error of
    // 0 exactly, and the edges now skip exactly collinear samples.
    let plane = GridSpec {
        width: 31,
        height: 22,
        values: (0..31 * 22)
            .map(|i: i32| f64::from(3 * (i % 31) - 7 * (i / 31) + 100))
            .collect(),
    };
    let (w, report) = run(&plane, 0.0, ErrorModel::Exact, 11, 2);
    assert_bound_holds(&plane, 0.0, &w, &report);
    assert_eq!((report.final_vertices, report.final_triangles), (16, 18));
    // A roof with a ridge, a step and a hole: planar pieces, kinks on and off tile edges.
    let roof = GridSpec {
        width: 37,
        height: 29,
        values: (0..37 * 29i32)
            .map(|i| {
                let (x, y) = (i % 37, i / 37);
                f64::from((x - 15).abs() + 2 * y + if x > 25 { 9 } else { 0 })
            })
            .collect(),
    };
    let roof = with_nodata_disc(roof, 20.0, 12.0, 3.0);
    for size in 2..10 {
        let (w, report) = run(&roof, 0.0, ErrorModel::Exact, size, 2);
        assert_bound_holds(&roof, 0.0, &w, &report);
        assert_crack_free(&roof, &w);
        assert_shared_edges_identical(&roof, &w, &report);
        if size >= 6 {
            assert!(
                report.final_triangles * 3 < report.initial_triangles,
                "tiles of {size}: {} of {} triangles kept",
                report.final_triangles,
                report.initial_triangles
            );
        }
    }
}

#[test]
fn same_mesh_for_one_and_two_threads_and_run_to_run() {
    let spec = with_nodata_disc(terrain(60, 45, 4.0, 11), 30.0, 22.0, 4.0);
    let (one, _) = run(&spec, 1.5, ErrorModel::Bounds, 9, 1);
    let (two, _) = run(&spec, 1.5, ErrorModel::Bounds, 9, 2);
    let (again, _) = run(&spec, 1.5, ErrorModel::Bounds, 9, 2);
    let (four, _) = run(&spec, 1.5, ErrorModel::Bounds, 9, 4);
    assert_eq!(one, two);
    assert_eq!(two, again);
    assert_eq!(two, four);
}

#[test]
fn count_targets_and_infinite_bounds_are_refused() {
    let grid = grid_of(&terrain(10, 10, 1.0, 1));
    let mut sink = Welded::default();
    for options in [
        DecimationOptions::new(1.0).with_max_triangles(10),
        DecimationOptions::new(f64::INFINITY),
        DecimationOptions::new(-1.0),
    ] {
        let err = mesh_tiles(
            &GridSource::new(&grid),
            &TileOptions::new(options),
            &mut sink,
            &mut |_| {},
        )
        .expect_err("refused");
        assert!(matches!(err, tinsmith_tiling::Error::Options(_)), "{err:?}");
    }
    assert!(sink.triangles.is_empty());
}

#[test]
fn a_failing_sink_stops_the_run_at_its_tile() {
    struct FailAt(usize, usize);
    impl TileSink for FailAt {
        fn tile(&mut self, _: &FinishedTile) -> Result<(), SinkError> {
            self.1 += 1;
            if self.1 == self.0 {
                Err("disk full".into())
            } else {
                Ok(())
            }
        }
    }
    let grid = grid_of(&terrain(30, 30, 1.0, 1));
    let mut sink = FailAt(5, 0);
    let err = mesh_tiles(
        &GridSource::new(&grid),
        &TileOptions::new(DecimationOptions::new(1.0)).with_tile_size(5),
        &mut sink,
        &mut |_| {},
    )
    .expect_err("sink fails");
    assert_eq!(
        err.to_string(),
        "tile (row 0, column 4): writing it failed",
        "{err:?}"
    );
    assert_eq!(sink.1, 5);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(96)))]

    #[test]
    fn random_grids_weld_within_the_bound_and_do_not_depend_on_threads(
        spec in small_grid().prop_filter("a cell", |g| g.width >= 2 && g.height >= 2),
        bound in max_error(),
        size in 2u32..9,
        exact in any::<bool>(),
    ) {
        let model = if exact { ErrorModel::Exact } else { ErrorModel::Bounds };
        let (w, report) = run(&spec, bound, model, size, 2);
        assert_bound_holds(&spec, bound, &w, &report);
        assert_crack_free(&spec, &w);
        assert_shared_edges_identical(&spec, &w, &report);
        let (one, _) = run(&spec, bound, model, size, 1);
        prop_assert_eq!(one, w);
    }
}
