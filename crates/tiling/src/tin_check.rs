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
