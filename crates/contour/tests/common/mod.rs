//! Helpers shared by the contour crate's integration tests: random levels over a grid
//! spec, and the meshes to contour (the full grid and a decimated TIN).

use tinsmith_contour::ContourMesh;
use tinsmith_core::{decimate, DecimationOptions, Grid, VertexHeights};
use tinsmith_testkit::{GridSpec, SplitMix};

/// Levels: some between samples, some exactly at sample values (the degenerate case).
pub fn levels_for(spec: &GridSpec, seed: u64) -> Vec<f64> {
    let valid: Vec<f64> = spec
        .values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    if valid.is_empty() {
        return vec![0.0];
    }
    let lo = valid.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = valid.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut rng = SplitMix::new(seed);
    let mut levels: Vec<f64> = (0..4).map(|_| lo + (hi - lo) * rng.unit()).collect();
    for _ in 0..4 {
        levels.push(valid[(rng.next_u64() % valid.len() as u64) as usize]);
    }
    levels
}

/// The full grid's mesh and TINs of it decimated within `e`: with vertices at their
/// samples (levels at sample values land on vertices), then with raised heights.
pub fn meshes(spec: &GridSpec, e: f64) -> Vec<ContourMesh> {
    let mut out = vec![ContourMesh::from_grid(spec.width, spec.height, &spec.values).unwrap()];
    let grid = Grid::new(spec.width, spec.height, spec.values.clone()).unwrap();
    for heights in [VertexHeights::Samples, VertexHeights::Raised] {
        let options = DecimationOptions::new(e).with_vertex_heights(heights);
        let tin = decimate(&grid, &options).unwrap().tin;
        let v = tin
            .vertices()
            .iter()
            .map(|v| [v.x as f64, v.y as f64, v.z])
            .collect();
        out.push(ContourMesh::new(v, tin.triangles().to_vec()).unwrap());
    }
    out
}
