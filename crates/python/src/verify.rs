//! `tinsmith.verify`: the independent verifier (`tinsmith-verify`, no code shared with the
//! decimator) on any TIN of an array, as `tinsmith verify` runs it on a mesh file.

use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tinsmith_georef::{Placement, F64_SAMPLE_TOLERANCE};
use tinsmith_verify::{GridRef, MeshRef, Orientation, VerifyOptions};

use crate::tin::Georef;

/// The Rust side of `tinsmith.verify`.
#[pyfunction]
#[pyo3(signature = (heights, vertices, triangles, max_error=None, nodata=None, mask=None, transform=None))]
#[allow(clippy::too_many_arguments)]
pub fn verify<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    vertices: PyReadonlyArray2<'py, f64>,
    triangles: PyReadonlyArray2<'py, i64>,
    max_error: Option<f64>,
    nodata: Option<f64>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    transform: Option<[f64; 6]>,
) -> PyResult<Bound<'py, PyDict>> {
    let (rows, columns) = crate::heights::shape(heights)?;
    // The grid as f64, the verifier's coverage bits and the mesh.
    crate::heights::check_fits(columns as u64, rows as u64, 24, 0, "verifying")?;
    let georef = Georef::new(transform, columns as u32, rows as u32)?;
    let placement = georef.placement();
    let grid = crate::heights::read(heights, nodata, mask.as_ref())?;
    let vertices = vertices.as_array();
    let triangles = triangles.as_array();
    if vertices.ncols() != 3 || triangles.ncols() != 3 {
        return Err(PyValueError::new_err(
            "vertices must be N x 3 (x, y, z) and triangles M x 3 (indices)",
        ));
    }
    let mut positions = Vec::with_capacity(vertices.nrows());
    let mut heights = Vec::with_capacity(vertices.nrows());
    for (i, v) in vertices.rows().into_iter().enumerate() {
        let p = placement
            .sample_at([v[0], v[1]], F64_SAMPLE_TOLERANCE)
            .map_err(|e| PyValueError::new_err(format!("vertex {i}: {e}")))?;
        positions.push(p);
        heights.push(v[2]);
    }
    let mut tris = Vec::with_capacity(triangles.nrows());
    for (i, t) in triangles.rows().into_iter().enumerate() {
        let mut corners = [0u32; 3];
        for (c, &index) in corners.iter_mut().zip(t.iter()) {
            *c = u32::try_from(index).map_err(|_| {
                PyValueError::new_err(format!("triangle {i}: index {index} is not a vertex"))
            })?;
        }
        tris.push(corners);
    }
    // Counter-clockwise in the written coordinates: clockwise in grid coordinates when
    // the transform flips orientation, as `tinsmith verify` expects.
    let orientation = match placement {
        Placement::World(_) if placement.flips_orientation() => Orientation::Clockwise,
        _ => Orientation::CounterClockwise,
    };
    let mut options = VerifyOptions::new().with_orientation(orientation);
    if let Some(e) = max_error {
        options = options.with_max_error(e);
    }
    let report = py
        .detach(|| {
            tinsmith_verify::verify(
                GridRef::new(grid.width(), grid.height(), grid.values()),
                MeshRef::new(&positions, &heights, &tris),
                &options,
            )
        })
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("passed", report.passed())?;
    d.set_item("mesh_is_valid", report.mesh_is_valid())?;
    d.set_item("within_bound", report.within_bound())?;
    d.set_item("width", report.width)?;
    d.set_item("height", report.height)?;
    d.set_item("valid_samples", report.valid_samples)?;
    d.set_item("domain_samples", report.domain_samples)?;
    d.set_item("isolated_samples", report.isolated_samples)?;
    d.set_item("valid_cells", report.valid_cells)?;
    d.set_item("vertices", report.vertices)?;
    d.set_item("triangles", report.triangles)?;
    d.set_item("max_error", report.max_error)?;
    d.set_item("max_error_allowed", report.max_error_allowed)?;
    match &report.max_error_at {
        Some(at) => {
            let loc = PyDict::new(py);
            loc.set_item("x", at.x)?;
            loc.set_item("y", at.y)?;
            loc.set_item("sample", at.sample)?;
            loc.set_item("interpolated", at.interpolated)?;
            loc.set_item("triangle", at.triangle)?;
            d.set_item("max_error_at", loc)?;
        }
        None => d.set_item("max_error_at", py.None())?,
    }
    d.set_item("uncovered_samples", report.uncovered_samples)?;
    d.set_item("degenerate_triangles", report.degenerate_triangles)?;
    d.set_item("flipped_triangles", report.flipped_triangles)?;
    d.set_item("unmeasured_triangles", report.unmeasured_triangles)?;
    d.set_item("nodata_covered_samples", report.nodata_covered_samples)?;
    d.set_item("bad_vertices", report.bad_vertices)?;
    d.set_item("bad_indices", report.bad_indices)?;
    d.set_item("open_edges", report.open_edges)?;
    d.set_item("overlapping_edges", report.overlapping_edges)?;
    d.set_item("problems", report.problems.clone())?;
    Ok(d)
}
