//! Points per second through the Delaunay triangulation, against spade's bulk load of the
//! same points in the same run (the baseline the insertion order replaced):
//!
//! ```sh
//! cargo run --release -p tinsmith-points --example triangulation_rate -- POINTS.csv [RUNS]
//! ```
//!
//! Reads and deduplicates the file as `tinsmith mesh` does, then times, alternately,
//! `tinsmith_points::delaunay` and a bulk load with the triangles read out the same way;
//! prints each run and the median rates and their ratio.

use std::path::Path;
use std::time::Instant;

use spade::{DelaunayTriangulation, Point2, Triangulation};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: triangulation_rate POINTS [RUNS]");
    let runs: usize = args
        .next()
        .map_or(3, |r| r.parse().expect("RUNS is a count"));
    let options = tinsmith_points::ReadOptions::default();
    let mut cloud = tinsmith_points::read_points(Path::new(&path), &options).expect("readable");
    tinsmith_points::dedupe(&mut cloud, tinsmith_points::Duplicates::Lowest);
    let n = cloud.xy.len();
    let (mut ours, mut bulk) = (Vec::new(), Vec::new());
    for run in 0..runs {
        let t = Instant::now();
        let triangles = tinsmith_points::delaunay(&cloud).expect("a triangulation");
        ours.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let sites: Vec<Point2<f64>> = cloud
            .xy
            .iter()
            .map(|p| Point2::new(p[0] as f64, p[1] as f64))
            .collect();
        let loaded: DelaunayTriangulation<Point2<f64>> =
            DelaunayTriangulation::bulk_load(sites).expect("a triangulation");
        let bulk_triangles: Vec<[usize; 3]> = loaded
            .inner_faces()
            .map(|f| f.vertices().map(|v| v.fix().index()))
            .collect();
        bulk.push(t.elapsed().as_secs_f64());
        assert_eq!(triangles.len(), bulk_triangles.len());
        println!(
            "run {run}: {n} points, {} triangles: {:.2} s, bulk load {:.2} s",
            triangles.len(),
            ours[run],
            bulk[run]
        );
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (a, b) = (median(&mut ours), median(&mut bulk));
    println!(
        "median: {:.2} M points/s, bulk load {:.2} M points/s ({:.2} x)",
        n as f64 / a / 1e6,
        n as f64 / b / 1e6,
        b / a
    );
}
