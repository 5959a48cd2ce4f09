//! The TIN's surface at the grid's samples, as the check measures it.

use crate::predicates::interpolate;
use crate::scan_convert::rasterize;
use crate::{MeshRef, Result, VerifyError};

/// The TIN's height at every sample of a `width x height` grid (row-major) that one of its
/// triangles covers, interpolated exactly as [`verify`](crate::verify) interpolates it;
/// NaN where no triangle does. Where triangles overlap, the last one wins. Triangles with
/// an index past the vertices are skipped.
///
/// # Errors
/// [`VerifyError::MeshSize`] if `mesh.heights.len() != mesh.positions.len()`.
pub fn surface(width: u32, height: u32, mesh: MeshRef<'_>) -> Result<Vec<f64>> {
    if mesh.heights.len() != mesh.positions.len() {
        return Err(VerifyError::MeshSize {
            positions: mesh.positions.len(),
            heights: mesh.heights.len(),
        });
    }
    let mut out = vec![f64::NAN; width as usize * height as usize];
    for triangle in mesh.triangles {
        let Some(corners) = triangle
            .iter()
            .map(|&i| {
                mesh.positions
                    .get(i as usize)
                    .map(|&p| (p, mesh.heights[i as usize]))
            })
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let positions = [corners[0].0, corners[1].0, corners[2].0];
        let heights = [corners[0].1, corners[1].1, corners[2].1];
        rasterize(positions, width, height, |x, y, weights| {
            out[y as usize * width as usize + x as usize] = interpolate(weights, heights);
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covered_samples_get_the_planes_heights_and_the_rest_nan() {
        // One triangle over the lower-left half of a 3 x 3 grid: z = x + 10 y.
        let positions = [[0, 0], [2, 0], [0, 2]];
        let heights = [0.0, 2.0, 20.0];
        let triangles = [[0, 1, 2]];
        let z = surface(3, 3, MeshRef::new(&positions, &heights, &triangles)).unwrap();
        for (k, v) in z.iter().enumerate() {
            let (x, y) = ((k % 3) as f64, (k / 3) as f64);
            if x + y <= 2.0 {
                assert_eq!(*v, x + 10.0 * y, "{x} {y}");
            } else {
                assert!(v.is_nan(), "{x} {y}");
            }
        }
    }
}
