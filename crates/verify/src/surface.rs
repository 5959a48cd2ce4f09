//! The TIN's surface at the grid's samples, as the check measures it.

use crate::predicates::interpolate;
use crate::scan_convert::{rasterize, rasterize_rows};
use crate::{MeshRef, Result, VerifyError};

/// The TIN's height at every sample of a `width x height` grid (row-major) that one of its
/// triangles covers, interpolated exactly as [`verify`](crate::verify) interpolates it;
/// NaN where no triangle does. Where triangles overlap, the last one wins. Triangles with
/// an index past the vertices are skipped.
///
/// # Errors
/// [`VerifyError::MeshSize`] if `mesh.heights.len() != mesh.positions.len()`.
pub fn surface(width: u32, height: u32, mesh: MeshRef<'_>) -> Result<Vec<f64>> {
    let mut out = vec![f64::NAN; width as usize * height as usize];
    for (positions, heights) in triangles(mesh)? {
        rasterize(positions, width, height, |x, y, weights| {
            out[y as usize * width as usize + x as usize] = interpolate(weights, heights);
        });
    }
    Ok(out)
}

/// Each triangle's corner positions and heights; triangles with an index past the
/// vertices are left out.
///
/// # Errors
/// [`VerifyError::MeshSize`] if `mesh.heights.len() != mesh.positions.len()`.
fn triangles<'a>(
    mesh: MeshRef<'a>,
) -> Result<impl Iterator<Item = ([[i64; 2]; 3], [f64; 3])> + 'a> {
    if mesh.heights.len() != mesh.positions.len() {
        return Err(VerifyError::MeshSize {
            positions: mesh.positions.len(),
            heights: mesh.heights.len(),
        });
    }
    Ok(mesh.triangles.iter().filter_map(move |t| {
        let corner = |k: usize| {
            let i = t[k] as usize;
            mesh.positions.get(i).map(|&p| (p, mesh.heights[i]))
        };
        let (a, b, c) = (corner(0)?, corner(1)?, corner(2)?);
        Some(([a.0, b.0, c.0], [a.1, b.1, c.1]))
    }))
}

/// The TIN's height at the samples of a `width x height` grid in the given `columns` and
/// `rows` (each strictly increasing, inside the grid), as [`surface`] gives it there but
/// without holding the whole grid: `columns.len() * rows.len()` values, row-major, NaN
/// where no triangle covers the sample. Time is linear in the triangles' rows plus the
/// samples they cover in the given rows; memory in the grid's width plus the result.
///
/// # Errors
/// [`VerifyError::MeshSize`] as [`surface`]; [`VerifyError::Lattice`] when `columns` or
/// `rows` is not strictly increasing inside the grid.
pub fn surface_at(
    width: u32,
    height: u32,
    mesh: MeshRef<'_>,
    columns: &[u32],
    rows: &[u32],
) -> Result<Vec<f64>> {
    let corners = triangles(mesh)?;
    let column_index = lattice_index(columns, width, "columns")?;
    let row_index = lattice_index(rows, height, "rows")?;
    let mut out = vec![f64::NAN; columns.len() * rows.len()];
    for (positions, heights) in corners {
        let keep_row = |y: u32| row_index[y as usize] != u32::MAX;
        rasterize_rows(positions, width, height, keep_row, |x, y, weights| {
            let column = column_index[x as usize];
            if column != u32::MAX {
                let row = row_index[y as usize] as usize;
                out[row * columns.len() + column as usize] = interpolate(weights, heights);
            }
        });
    }
    Ok(out)
}

/// For each of `side` samples, its place in `picked` (strictly increasing, each below
/// `side`), or `u32::MAX` when not picked.
fn lattice_index(picked: &[u32], side: u32, what: &'static str) -> Result<Vec<u32>> {
    let increasing = picked.windows(2).all(|w| w[0] < w[1]);
    if !increasing || picked.last().is_some_and(|&last| last >= side) {
        return Err(VerifyError::Lattice { what, side });
    }
    let mut index = vec![u32::MAX; side as usize];
    for (k, &p) in picked.iter().enumerate() {
        index[p as usize] = k as u32;
    }
    Ok(index)
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

    #[test]
    fn surface_at_picks_the_surface_at_the_given_samples() {
        let positions = [[0, 0], [6, 0], [6, 4], [0, 4], [3, 2]];
        let heights = [0.0, 6.0, 46.0, 40.0, 23.5];
        let triangles = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let mesh = MeshRef::new(&positions, &heights, &triangles);
        let whole = surface(8, 5, mesh).unwrap();
        let (columns, rows) = ([0, 2, 3, 6, 7], [1, 4]);
        let some = surface_at(8, 5, mesh, &columns, &rows).unwrap();
        assert_eq!(some.len(), 10);
        for (j, &y) in rows.iter().enumerate() {
            for (i, &x) in columns.iter().enumerate() {
                let (a, b) = (some[j * 5 + i], whole[y as usize * 8 + x as usize]);
                assert!(a == b || (a.is_nan() && b.is_nan()), "{x} {y}: {a} {b}");
            }
        }
        assert!(some[4].is_nan(), "column 7 is outside the mesh");
        for (columns, rows) in [(&[2, 2][..], &[1][..]), (&[8], &[1]), (&[1], &[3, 2])] {
            assert!(matches!(
                surface_at(8, 5, mesh, columns, rows),
                Err(VerifyError::Lattice { .. })
            ));
        }
    }
}
