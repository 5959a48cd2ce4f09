//! The independent check every decimated TIN passes before it is written: the verifier's
//! true error at every sample of its grid, on the heights as they will be stored.

use tinsmith_core::{Grid, Tin, TinVertex};
use tinsmith_verify::{GridRef, MeshRef, Report, VerifyOptions};

/// Measures `tin` against the samples of `grid` with the independent verifier
/// (`tinsmith-verify`, which shares no code with the decimator), each vertex at the height
/// `stored(index, vertex)` gives (its height as the file or tile will hold it), against
/// `max_error`. The report says whether the TIN passed ([`Report::passed`]) and, if not,
/// why.
pub fn check_tin(
    grid: &Grid,
    tin: &Tin,
    stored: impl Fn(usize, &TinVertex) -> f64,
    max_error: f64,
) -> tinsmith_verify::Result<Report> {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let heights: Vec<f64> = tin
        .vertices()
        .iter()
        .enumerate()
        .map(|(i, v)| stored(i, v))
        .collect();
    tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &heights, tin.triangles()),
        &VerifyOptions::new().with_max_error(max_error),
    )
}

/// Measures variable `values` (samples on `grid`, whose nodata is the domain) on `tin`,
/// the variable's value at each vertex being `at_vertices[i]`, with the independent
/// verifier, against `max_error` (infinite: measured, never failing).
pub fn check_variable(
    grid: &Grid,
    values: &[f64],
    tin: &Tin,
    at_vertices: &[f64],
    max_error: f64,
) -> tinsmith_verify::Result<Report> {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let mut options = VerifyOptions::new();
    if max_error.is_finite() {
        options = options.with_max_error(max_error);
    }
    tinsmith_verify::verify_variable(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        values,
        MeshRef::new(&positions, &[], tin.triangles()),
        at_vertices,
        &options,
    )
}
