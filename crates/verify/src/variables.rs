//! Several variables over one mesh: each variable checked as its own surface over the
//! height's domain, with the mesh's positions and triangles and its own vertex values.

use crate::{verify, GridRef, MeshRef, Report, Result, VerifyError, VerifyOptions};

/// Checks one variable of `mesh`: [`verify`] of the variable's samples, made nodata
/// wherever `domain` (the height grid, nodata wherever any variable is) is nodata, against
/// the mesh's positions and triangles with `vertex_values` (the variable's value at each
/// vertex) as heights. The report's error is the variable's, measured at every covered
/// sample; its coverage and conformity findings are the mesh's.
///
/// # Errors
/// [`VerifyError::GridSize`] when `values` is not `domain`'s size; as [`verify`] otherwise.
pub fn verify_variable(
    domain: GridRef<'_>,
    values: &[f64],
    mesh: MeshRef<'_>,
    vertex_values: &[f64],
    options: &VerifyOptions,
) -> Result<Report> {
    if values.len() != domain.values.len() {
        return Err(VerifyError::GridSize {
            width: domain.width,
            height: domain.height,
            expected: u64::from(domain.width) * u64::from(domain.height),
            actual: values.len(),
        });
    }
    let masked: Vec<f64> = domain
        .values
        .iter()
        .zip(values)
        .map(|(h, v)| if h.is_finite() { *v } else { f64::NAN })
        .collect();
    verify(
        GridRef::new(domain.width, domain.height, &masked),
        MeshRef::new(mesh.positions, vertex_values, mesh.triangles),
        options,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_the_variable_over_the_heights_domain() {
        // Two triangles over a 3x3 grid whose corner (2, 2) is nodata in the height: the
        // variable's value there is ignored, its bump at the centre measured.
        let nan = f64::NAN;
        let heights = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, nan];
        let variable = [1.0, 1.0, 1.0, 1.0, 4.0, 1.0, 1.0, 1.0, 99.0];
        let positions = [[0, 0], [2, 0], [0, 2]];
        let triangles = [[0, 1, 2]];
        let domain = GridRef::new(3, 3, &heights);
        let mesh = MeshRef::new(&positions, &[0.0; 3], &triangles);
        let report = verify_variable(
            domain,
            &variable,
            mesh,
            &[1.0, 1.0, 1.0],
            &VerifyOptions::new().with_max_error(2.5),
        )
        .unwrap();
        assert_eq!(report.max_error, 3.0);
        assert!(!report.within_bound());
        assert!(verify_variable(
            domain,
            &variable[..8],
            mesh,
            &[1.0; 3],
            &VerifyOptions::new()
        )
        .is_err());
    }
}
