//! `tinsmith.contour`: contour lines of the full grid, or of its TIN decimated within
//! `max_error`, as `tinsmith contour` traces them (`tinsmith-contour`).

use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tinsmith_contour::ContourMesh;
use tinsmith_core::{decimate_with_progress, DecimationOptions, Grid};

use crate::interrupt::Interruptible;
use crate::tin::Georef;

/// The Rust side of `tinsmith.contour`: `(level, closed, points)` per line, points in the
/// transform's coordinates (or (column, row)).
#[pyfunction]
#[pyo3(signature = (heights, interval=None, levels=None, offset=None, max_error=None, simplify=None, nodata=None, mask=None, transform=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn contour<'py>(
    py: Python<'py>,
    heights: &Bound<'py, PyAny>,
    interval: Option<f64>,
    levels: Option<Vec<f64>>,
    offset: Option<f64>,
    max_error: Option<f64>,
    simplify: Option<f64>,
    nodata: Option<f64>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    transform: Option<[f64; 6]>,
) -> PyResult<Vec<(f64, bool, Vec<[f64; 2]>)>> {
    let (rows, columns) = crate::heights::shape(heights)?;
    // The full grid's TIN has two triangles a cell (the CLI's 120 bytes a sample).
    crate::heights::check_fits(
        columns as u64,
        rows as u64,
        tinsmith_tiling::WHOLE_GRID_BYTES_PER_SAMPLE,
        0,
        "contouring",
    )?;
    let placement = Georef::new(transform, columns as u32, rows as u32)?.placement();
    let read = crate::heights::read(heights, nodata, mask.as_ref())?;
    let value = |e: tinsmith_contour::Error| PyValueError::new_err(e.to_string());
    let (width, height) = (read.width(), read.height());
    let grid_values = read.values();
    let interrupt = Interruptible::new();
    let result = py.detach(|| -> Result<_, crate::Failure> {
        let mesh = match max_error.filter(|&e| e > 0.0) {
            None => ContourMesh::from_grid(width, height, grid_values)
                .map_err(|e| crate::Failure::Value(e.to_string()))?,
            Some(e) => {
                let grid = Grid::from_samples(read.clone());
                let options = DecimationOptions::new(e);
                let d = interrupt
                    .run(|| decimate_with_progress(&grid, &options, &mut |_| interrupt.check()))?
                    .map_err(|e| crate::Failure::Value(e.to_string()))?;
                let vertices = d
                    .tin
                    .vertices()
                    .iter()
                    .map(|v| [f64::from(v.x), f64::from(v.y), v.z])
                    .collect();
                ContourMesh::new(vertices, d.tin.triangles().to_vec())
                    .map_err(|e| crate::Failure::Value(e.to_string()))?
            }
        };
        Ok(mesh)
    });
    let mesh = interrupt.finish(py, result)?;
    let levels = match (interval, levels) {
        (Some(_), Some(_)) => {
            return Err(PyValueError::new_err("give interval or levels, not both"))
        }
        (Some(interval), None) => match mesh.height_range() {
            Some((lo, hi)) => {
                tinsmith_contour::interval_levels(interval, offset.unwrap_or(0.0), lo, hi)
                    .map_err(value)?
            }
            None => Vec::new(),
        },
        (None, Some(levels)) => levels,
        (None, None) => return Err(PyValueError::new_err("give interval or levels")),
    };
    let lines = py
        .detach(|| tinsmith_contour::contour(&mesh, &levels))
        .map_err(value)?;
    let mut out = Vec::with_capacity(lines.len());
    for line in &lines {
        let points: Vec<[f64; 2]> = line
            .points()
            .iter()
            .map(|&p| placement.file_point(p))
            .collect();
        let points = match simplify {
            Some(tolerance) => tinsmith_contour::simplify_indices(&points, tolerance)
                .into_iter()
                .map(|i| points[i])
                .collect(),
            None => points,
        };
        out.push((line.level(), line.is_closed(), points));
    }
    Ok(out)
}
