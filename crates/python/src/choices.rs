//! The options of `tinsmith.mesh`, named and meaning as `tinsmith mesh --help` has them,
//! turned into the core's `DecimationOptions`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tinsmith_core::{
    DecimationOptions, EdgeSelection, ErrorModel, InitialMesh, Order, Retriangulation,
    VertexHeights,
};

/// What a `mesh` call asks for, besides the array and its georeferencing.
#[derive(Debug, Clone)]
pub struct MeshChoices {
    pub max_error: Option<f64>,
    pub max_triangles: Option<usize>,
    pub max_vertices: Option<usize>,
    pub error_model: ErrorModel,
    pub selection: EdgeSelection,
    pub order: Order,
    pub retriangulate: Retriangulation,
    pub dp_max_ring: u16,
    pub initial_mesh: InitialMesh,
    pub max_edge_length: Option<u32>,
    pub flip_rounds: usize,
    pub extend_rounds: usize,
    pub vertex_heights: VertexHeights,
    pub contour_interval: Option<f64>,
    pub contour_offset: Option<f64>,
    pub contour_levels: Vec<f64>,
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
    /// Whether a triangle or vertex count is the target.
    pub fn has_count_target(&self) -> bool {
        self.max_triangles.is_some() || self.max_vertices.is_some()
    }

    /// The decimation options asked for, as the CLI builds them
    /// (`tinsmith_pipeline::MeshJob::decimation_options`), with `bound` as the bound (the
    /// asked one less a float32 format's height rounding): contour levels from
    /// `contour_interval` run over `heights`, the array's valid range.
    pub fn decimation_options(
        &self,
        bound: f64,
        heights: Option<(f64, f64)>,
    ) -> PyResult<DecimationOptions> {
        if self.max_error.is_none() && !self.has_count_target() {
            return Err(PyValueError::new_err(
                "give max_error, or a count target (max_triangles or max_vertices)",
            ));
        }
        let mut options = DecimationOptions::new(bound)
            .with_selection(self.selection)
            .with_error_model(self.error_model)
            .with_order(self.order)
            .with_retriangulation(self.retriangulate)
            .with_initial_mesh(self.initial_mesh);
        options.dp_max_ring = self.dp_max_ring as usize;
        options.max_edge_length = self.max_edge_length;
        options.flip_rounds = self.flip_rounds;
        options.extend_rounds = self.extend_rounds;
        options.vertex_heights = self.vertex_heights;
        if self.has_count_target() && (self.flip_rounds > 0 || self.extend_rounds > 0) {
            return Err(PyValueError::new_err(
                "flip_rounds and extend_rounds work to an error bound, not with max_triangles \
                 or max_vertices",
            ));
        }
        if let Some(n) = self.max_triangles {
            options = options.with_max_triangles(n);
        }
        if let Some(n) = self.max_vertices {
            options = options.with_max_vertices(n);
        }
        let contour = |r: tinsmith_contour::Result<Vec<f64>>| {
            r.map_err(|e| PyValueError::new_err(e.to_string()))
        };
        let levels = match (self.contour_interval, heights) {
            (Some(interval), Some((lo, hi))) => {
                let offset = self.contour_offset.unwrap_or(0.0);
                Some(contour(tinsmith_contour::interval_levels(
                    interval, offset, lo, hi,
                ))?)
            }
            (Some(_), None) => Some(Vec::new()),
            (None, _) if !self.contour_levels.is_empty() => Some(contour(
                tinsmith_contour::sorted_levels(&self.contour_levels),
            )?),
            (None, _) => None,
        };
        if let Some(levels) = levels {
            options = options.with_contour_levels(&levels);
        }
        Ok(options)
    }
}
