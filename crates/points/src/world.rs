//! Points given as world coordinates (an OGR point layer, read by the caller) put on the
//! lattice the way an existing TIN's vertices are (see the `tin` module: the coarsest
//! power-of-ten step per axis that holds every coordinate, else their regular spacing).

use std::path::Path;

use crate::cloud::{ClassChoice, FileCrs, PointCloud};
use crate::error::{format_error, Result};
use crate::tin::axis_scale;

/// The points `[x, y, z]` of `path` as a cloud on their lattice, in the given order
/// (points at one lattice position are left for [`crate::dedupe`]).
///
/// # Errors
/// [`crate::Error::Format`] naming `path` for a non-finite value, or coordinates on no
/// lattice within `MAX_LATTICE` steps.
pub fn world_cloud(path: &Path, points: &[[f64; 3]]) -> Result<PointCloud> {
    if let Some(p) = points.iter().find(|p| p.iter().any(|v| !v.is_finite())) {
        return Err(format_error(path, format!("point {p:?} is not finite")));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let mut scale = [1.0f64; 2];
    if !points.is_empty() {
        for a in 0..2 {
            let values: Vec<f64> = points.iter().map(|p| p[a]).collect();
            scale[a] = axis_scale(&values, lo[a], hi[a])
                .map_err(|why| format_error(path, format!("{}: {why}", ["x", "y"][a])))?;
        }
    } else {
        lo = [0.0; 2];
    }
    Ok(PointCloud {
        xy: points
            .iter()
            .map(|p| {
                [
                    ((p[0] - lo[0]) * scale[0]).round() as i64,
                    ((p[1] - lo[1]) * scale[1]).round() as i64,
                ]
            })
            .collect(),
        z: points.iter().map(|p| p[2]).collect(),
        origin: lo,
        spacing: [1.0 / scale[0], 1.0 / scale[1]],
        crs: FileCrs::default(),
        classes: ClassChoice::All,
        points_in_file: points.len() as u64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centimetre_coordinates_go_on_a_centimetre_lattice() {
        let c = world_cloud(
            "p.gpkg".as_ref(),
            &[[100.25, 7.5, 1.0], [100.5, 8.0, 2.0], [101.0, 7.25, 3.0]],
        )
        .unwrap();
        assert_eq!(c.spacing, [0.01, 0.01]);
        assert_eq!(c.origin, [100.25, 7.25]);
        assert_eq!(c.xy, vec![[0, 25], [25, 75], [75, 0]]);
        let e = world_cloud("p.gpkg".as_ref(), &[[f64::NAN, 0.0, 0.0]]).unwrap_err();
        assert!(e.to_string().contains("p.gpkg"));
    }
}
