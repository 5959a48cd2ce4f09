//! The extension module of the `tinsmith` Python package (`tinsmith._tinsmith`): numpy
//! heights in, a TIN verified within its bound out, through the same library calls as the
//! `tinsmith` CLI (core, tiling, verify, formats, contour) with the same option names and
//! messages. No GDAL: rasters are read by the caller's own tools (rasterio, xarray).
//!
//! Every call releases the GIL while it decimates, verifies, contours or writes; Ctrl-C
//! interrupts a long call with `KeyboardInterrupt` (see `interrupt`). The Python API, its
//! docs and type stubs are in `python/tinsmith/`.

mod choices;
mod contour;
mod heights;
mod interrupt;
mod mesh;
mod tin;
mod verify;

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

create_exception!(
    _tinsmith,
    BoundError,
    PyException,
    "A mesh failed its own verification: the independent verifier measured an error \
     beyond the bound (never expected; nothing is returned or written)."
);

/// How an engine call running without the GIL failed.
pub enum Failure {
    /// Bad input or options: a `ValueError` with the message.
    Value(String),
    /// The result failed verification: a `BoundError`.
    Bound(String),
    /// A signal handler raised (see `interrupt`).
    Interrupted,
}

impl Failure {
    fn into_py_err(self, _py: Python<'_>) -> PyErr {
        match self {
            Failure::Value(m) => PyValueError::new_err(m),
            Failure::Bound(m) => BoundError::new_err(m),
            Failure::Interrupted => pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted"),
        }
    }
}

/// The mesh options from the Python wrapper's dict (every key present).
fn choices_from_dict(d: &Bound<'_, PyDict>) -> PyResult<choices::MeshChoices> {
    fn get<'py, T>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T>
    where
        T: for<'a> FromPyObject<'a, 'py>,
        for<'a> <T as FromPyObject<'a, 'py>>::Error: Into<PyErr>,
    {
        let value = d
            .get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("missing option {key}")))?;
        value.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            PyValueError::new_err(format!("{key}: {}", e.value(d.py())))
        })
    }
    let text = |key: &str| -> PyResult<String> { get::<String>(d, key) };
    let mut decimation = tinsmith_choices::DecimationChoices::default();
    decimation.max_error = get(d, "max_error")?;
    decimation.max_triangles = get(d, "max_triangles")?;
    decimation.max_vertices = get(d, "max_vertices")?;
    decimation.error_model = choices::error_model(&text("error_model")?)?;
    decimation.selection = choices::selection(&text("selection")?)?;
    decimation.order = choices::order(&text("order")?)?;
    decimation.retriangulate = choices::retriangulate(&text("retriangulate")?)?;
    decimation.dp_max_ring = get(d, "dp_max_ring")?;
    decimation.initial_mesh = choices::initial_mesh(&text("initial_mesh")?)?;
    decimation.max_edge_length = get(d, "max_edge_length")?;
    decimation.flip_rounds = get(d, "flip_rounds")?;
    decimation.extend_rounds = get(d, "extend_rounds")?;
    decimation.vertex_heights = choices::vertex_heights(&text("vertex_heights")?)?;
    decimation.contour_interval = get(d, "contour_interval")?;
    decimation.contour_offset = get(d, "contour_offset")?;
    decimation.contour_levels = get::<Option<Vec<f64>>>(d, "contour_levels")?.unwrap_or_default();
    Ok(choices::MeshChoices {
        decimation,
        tile_size: get(d, "tile_size")?,
        threads: get(d, "threads")?,
        format: match get::<Option<String>>(d, "format")? {
            Some(name) => Some(
                tinsmith_formats::MeshFormat::from_name(&name)
                    .map_err(|e| PyValueError::new_err(e.to_string()))?,
            ),
            None => None,
        },
    })
}

#[pymodule]
fn _tinsmith(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("BoundError", m.py().get_type::<BoundError>())?;
    m.add("DEFAULT_TILE_SIZE", tinsmith_tiling::DEFAULT_TILE_SIZE)?;
    m.add_class::<tin::Tin>()?;
    m.add_function(wrap_pyfunction!(mesh::mesh, m)?)?;
    m.add_function(wrap_pyfunction!(verify::verify, m)?)?;
    m.add_function(wrap_pyfunction!(contour::contour, m)?)?;
    Ok(())
}
