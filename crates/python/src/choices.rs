//! The options of `tinsmith.mesh`, named and meaning as `tinsmith mesh --help` has them:
//! the decimation in the CLI's own `DecimationChoices`, the rest (tiles, threads, format)
//! beside it.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tinsmith_choices::DecimationChoices;
use tinsmith_core::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};

/// What a `mesh` call asks for, besides the array and its georeferencing.
#[derive(Debug, Clone)]
pub struct MeshChoices {
    /// The decimation, as `tinsmith mesh` takes it (one struct for both).
    pub decimation: DecimationChoices,
    pub tile_size: u32,
    pub threads: Option<u32>,
    /// The format the mesh is for (`--format`): STL and glTF get the CLI's tighter bound.
    pub format: Option<tinsmith_formats::MeshFormat>,
}

/// `value` among `all` by the name the CLI gives it; a ValueError listing the names
/// otherwise, as the CLI's "invalid value" message does.
pub fn by_name<T: Copy>(
    option: &str,
    value: &str,
    all: &[T],
    name: impl Fn(T) -> &'static str,
) -> PyResult<T> {
    all.iter()
        .copied()
        .find(|&v| name(v) == value)
        .ok_or_else(|| {
            let names: Vec<_> = all.iter().map(|&v| name(v)).collect();
            PyValueError::new_err(format!(
                "invalid value '{value}' for {option} (possible values: {})",
                names.join(", ")
            ))
        })
}

pub fn error_model(v: &str) -> PyResult<ErrorModel> {
    by_name(
        "error_model",
        v,
        &[ErrorModel::Bounds, ErrorModel::Exact],
        ErrorModel::name,
    )
}

pub fn selection(v: &str) -> PyResult<EdgeSelection> {
    let all = [
        EdgeSelection::Hybrid,
        EdgeSelection::MinError,
        EdgeSelection::MinIntroduced,
    ];
    by_name("selection", v, &all, EdgeSelection::name)
}

pub fn order(v: &str) -> PyResult<Order> {
    by_name("order", v, &[Order::Sweep, Order::Greedy], Order::name)
}

pub fn retriangulate(v: &str) -> PyResult<Retriangulation> {
    let all = [Retriangulation::Dp, Retriangulation::Ears];
    by_name("retriangulate", v, &all, Retriangulation::name)
}

pub fn initial_mesh(v: &str) -> PyResult<InitialMesh> {
    let all = [
        InitialMesh::Auto,
        InitialMesh::Strips,
        InitialMesh::Rtin,
        InitialMesh::Full,
    ];
    by_name("initial_mesh", v, &all, InitialMesh::name)
}

pub fn vertex_heights(v: &str) -> PyResult<VertexHeights> {
    let all = [VertexHeights::Samples, VertexHeights::Raised];
    by_name("vertex_heights", v, &all, VertexHeights::name)
}

impl MeshChoices {
    /// The decimation options asked for, as the CLI builds them (one
    /// [`DecimationChoices::decimation_options`] for both), with `bound` as the bound;
    /// the refusals as `ValueError`s.
    pub fn decimation_options(
        &self,
        bound: f64,
        heights: Option<(f64, f64)>,
    ) -> PyResult<DecimationOptions> {
        use tinsmith_choices::ChoiceError;
        self.decimation
            .decimation_options(bound, heights)
            .map_err(|e| {
                // The choices' refusals in the binding's own argument names.
                PyValueError::new_err(match e {
                    ChoiceError::NoTarget => {
                        "give max_error, or a count target (max_triangles or max_vertices)"
                            .to_owned()
                    }
                    ChoiceError::RoundsWithCount => "flip_rounds and extend_rounds work to an \
                         error bound, not with max_triangles or max_vertices"
                        .to_owned(),
                    other => other.to_string(),
                })
            })
    }
}
