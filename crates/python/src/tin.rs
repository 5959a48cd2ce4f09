//! `tinsmith.Tin`: a verified TIN as numpy arrays, and its writers (the CLI's formats).

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyInt, PyString};
use tinsmith_formats::{LocalOrigin, MeshFormat, MeshRef, WriteOptions};
use tinsmith_georef::{GeoTransform, Placement, PlacementProblem};

use crate::BoundError;

/// Where an array's samples sit: the geotransform (GDAL order) or pixel coordinates, the
/// array's size and its valid height range (for the float32 formats' origin).
#[derive(Debug, Clone, Copy)]
pub struct Georef {
    transform: Option<GeoTransform>,
    width: u32,
    height: u32,
    heights: Option<(f64, f64)>,
}

impl Georef {
    /// Fails, as the CLI does for a raster's geotransform, when `transform` cannot give
    /// every sample its own position: a non-finite coefficient, a singular map, or pixels
    /// too small for the origin in `f64` (checked at the corners).
    pub fn new(transform: Option<[f64; 6]>, width: u32, height: u32) -> PyResult<Georef> {
        let georef = Georef {
            transform: transform.map(GeoTransform),
            width,
            height,
            heights: None,
        };
        let Some(t) = georef.transform else {
            return Ok(georef);
        };
        let problem = match georef.placement().check_places_samples(width, height) {
            Ok(()) => return Ok(georef),
            Err(PlacementProblem::NotFinite) => {
                "has a coefficient that is not a finite number".into()
            }
            Err(PlacementProblem::Singular) => {
                "is singular (a pixel size of 0: samples have no distinct positions)".into()
            }
            Err(PlacementProblem::PixelsTooSmall { x, y }) => format!(
                "has pixels too small for its origin: in f64 the position of sample ({x}, {y}) \
                 does not map back to it"
            ),
        };
        Err(PyValueError::new_err(format!(
            "transform {:?} {problem}",
            t.0
        )))
    }

    pub fn with_heights(mut self, heights: Option<(f64, f64)>) -> Georef {
        self.heights = heights;
        self
    }

    pub fn placement(&self) -> Placement {
        Placement::new(self.transform, false)
    }

    /// The float32 formats' origin, as the CLI chooses it: the middle of the sample
    /// centres' extent and of the valid heights.
    pub fn origin(&self) -> LocalOrigin {
        let ([x0, y0], [x1, y1]) = self.placement().extent(self.width, self.height);
        let (mut min, mut max) = ([x0, y0, 0.0], [x1, y1, 0.0]);
        let (lo, hi) = self.heights.unwrap_or((0.0, 0.0));
        min[2] = lo;
        max[2] = hi;
        LocalOrigin::around(min, max)
    }
}

/// A triangulated irregular network whose linear interpolation is within the bound of
/// every valid sample, as the independent verifier measured it.
#[pyclass(module = "tinsmith", frozen)]
pub struct Tin {
    vertices: Py<PyArray2<f64>>,
    triangles: Py<PyArray2<u32>>,
    measured_max_error: f64,
    bound: Option<f64>,
    report: Py<PyDict>,
    georef: Georef,
}

impl Tin {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        py: Python<'_>,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        measured_max_error: f64,
        bound: Option<f64>,
        report: Bound<'_, PyDict>,
        georef: Georef,
    ) -> PyResult<Tin> {
        let v = Array2::from_shape_vec((vertices.len(), 3), vertices.into_flattened())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let t = Array2::from_shape_vec((triangles.len(), 3), triangles.into_flattened())
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let v = v.into_pyarray(py);
        let t = t.into_pyarray(py);
        // Read-only views: the arrays are the verified mesh, shared by every access.
        for a in [v.as_any(), t.as_any()] {
            a.getattr("flags")?.setattr("writeable", false)?;
        }
        Ok(Tin {
            vertices: v.unbind(),
            triangles: t.unbind(),
            measured_max_error,
            bound,
            report: report.unbind(),
            georef,
        })
    }
}

#[pymethods]
impl Tin {
    /// Vertices, N x 3 float64 (x, y, z): world coordinates of the sample centres through
    /// the transform, or (column, row, value) without one. Read-only.
    #[getter]
    fn vertices(&self, py: Python<'_>) -> Py<PyArray2<f64>> {
        self.vertices.clone_ref(py)
    }

    /// Triangles, M x 3 uint32 indices into `vertices`, counter-clockwise in the written
    /// coordinates (normals up). Read-only.
    #[getter]
    fn triangles(&self, py: Python<'_>) -> Py<PyArray2<u32>> {
        self.triangles.clone_ref(py)
    }

    /// The largest |sample - TIN| over every valid sample, measured by the independent
    /// verifier (at most the `max_error` asked for).
    #[getter]
    fn max_error(&self) -> f64 {
        self.measured_max_error
    }

    /// The run's report: the fields of `tinsmith mesh --report` (counts before and after,
    /// the options, the bound kept and the measured error, seconds).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.report.bind(py).copy()
    }

    /// The TIN as a `trimesh.Trimesh` (trimesh must be importable), vertices and faces as
    /// they are (`process=False`).
    fn to_trimesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let trimesh = py.import("trimesh")?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("vertices", self.vertices.bind(py))?;
        kwargs.set_item("faces", self.triangles.bind(py))?;
        kwargs.set_item("process", false)?;
        trimesh.getattr("Trimesh")?.call((), Some(&kwargs))
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.triangles.bind(py).shape()[0]
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Tin({} vertices, {} triangles, max_error={})",
            self.vertices.bind(py).shape()[0],
            self.triangles.bind(py).shape()[0],
            self.measured_max_error
        )
    }

    /// Writes the TIN to `path` in `format` (a name: ply, obj, stl, glb, geojson, fgb,
    /// landxml; default from the extension) with `crs` (WKT text, "EPSG:n" or an EPSG
    /// code), as `tinsmith mesh -o` writes it: atomically (a temporary file renamed into
    /// place), a `.prj` sidecar beside OBJ, STL and glTF. GeoJSON keeps the array's CRS
    /// (the CLI's `--geojson-source-crs`). STL and glTF store float32 offsets from a local
    /// origin: mesh with `format="stl"` or `"glb"` to leave room for that rounding, as the
    /// CLI does; the file is refused (`BoundError`) when the rounding could take it past
    /// `max_error`. `base` (STL only, the CLI's `--base`) closes the surface into a solid
    /// with a floor at that height, below the lowest vertex; `normals` (glTF only,
    /// `--normals`) writes per-vertex normals.
    #[pyo3(signature = (path, format=None, crs=None, base=None, normals=false))]
    fn write(
        &self,
        py: Python<'_>,
        path: PathBuf,
        format: Option<&str>,
        crs: Option<&Bound<'_, PyAny>>,
        base: Option<f64>,
        normals: bool,
    ) -> PyResult<()> {
        let value = |e: tinsmith_formats::Error| PyValueError::new_err(e.to_string());
        let format = match format {
            Some(name) => MeshFormat::from_name(name).map_err(value)?,
            None => MeshFormat::from_path(&path).map_err(value)?,
        };
        for (given, name, only) in [
            (base.is_some(), "base", MeshFormat::Stl),
            (normals, "normals", MeshFormat::Glb),
        ] {
            if given && format != only {
                return Err(PyValueError::new_err(format!(
                    "{}: {name} applies to {only} output only, not {format}",
                    path.display()
                )));
            }
        }
        let (wkt, epsg) = crs_of(crs)?;
        let origin = format.is_float32().then(|| self.georef.origin());
        let vertices = self.vertices.bind(py).try_readonly()?;
        let triangles = self.triangles.bind(py).try_readonly()?;
        let (vertices, triangles) = (rows(vertices.as_slice()?), rows(triangles.as_slice()?));
        if let (Some(origin), Some(bound)) = (origin, self.bound) {
            // Every interpolated height moves by at most its corners' largest move.
            let rounding = vertices
                .iter()
                .map(|v| (origin.quantize([0.0, 0.0, v[2]])[2] - v[2]).abs())
                .fold(0.0, f64::max);
            if self.measured_max_error + rounding > bound {
                return Err(BoundError::new_err(format!(
                    "{}: float32 heights round by up to {rounding}, which could take the \
                     measured error {} past max_error {bound}; mesh with a smaller \
                     max_error or write a double-precision format (ply, obj, fgb, \
                     geojson, landxml)",
                    path.display(),
                    self.measured_max_error
                )));
            }
        }
        if let Some(origin) = origin {
            // As the CLI's last gate for float32 files: every stored position maps back to
            // its sample as `tinsmith verify` will map it.
            let placement = self.georef.placement();
            for (i, v) in vertices.iter().enumerate() {
                let q = origin.quantize(*v);
                if placement
                    .sample_at([q[0], q[1]], tinsmith_georef::F32_SAMPLE_TOLERANCE)
                    .is_err()
                {
                    return Err(PyValueError::new_err(format!(
                        "{}: vertex {i} would not map back to its sample in float32 (the \
                         array is too large for float32 positions relative to one origin); \
                         nothing written; use a double-precision format (ply, obj, fgb, \
                         geojson, landxml)",
                        path.display()
                    )));
                }
            }
        }
        if let (Some(base), Some(origin)) = (base, origin) {
            let lowest = vertices.iter().map(|v| v[2]).fold(f64::INFINITY, f64::min);
            if !base.is_finite() || base >= lowest {
                return Err(PyValueError::new_err(format!(
                    "{}: base {base} must be a finite height below the lowest vertex \
                     ({lowest})",
                    path.display()
                )));
            }
            // The floor is written as float32 like every other coordinate.
            if !((base - origin.offset()[2]) as f32).is_finite() {
                return Err(PyValueError::new_err(format!(
                    "{}: base {base} is beyond the range of the format's float32 coordinates",
                    path.display()
                )));
            }
        }
        let options = WriteOptions::new()
            .with_origin(origin)
            .with_base(base)
            .with_normals(normals);
        let mesh = MeshRef::new(vertices, triangles)
            .with_crs_wkt(wkt.as_deref())
            .with_epsg(epsg);
        py.detach(|| tinsmith_formats::write_mesh_with(&path, format, mesh, &options))
            .map_err(|e| PyValueError::new_err(crate::mesh::error_chain(&e)))
    }
}

/// The EPSG code of a WKT's root (its `ID["EPSG",n]` or `AUTHORITY["EPSG","n"]` at the
/// outermost level, as GDAL's `GetAuthorityCode(NULL)` reads it), if it has one.
fn wkt_epsg(wkt: &str) -> Option<u32> {
    let mut depth = 0usize;
    let mut found = None;
    for (i, c) in wkt.char_indices() {
        match c {
            '[' | '(' => depth += 1,
            ']' | ')' => depth = depth.saturating_sub(1),
            _ if depth == 1 => {
                let rest = &wkt[i..];
                for key in ["ID[\"EPSG\",", "AUTHORITY[\"EPSG\",\""] {
                    if let Some(tail) = rest.strip_prefix(key) {
                        let digits: String =
                            tail.chars().take_while(|c| c.is_ascii_digit()).collect();
                        found = digits.parse().ok().or(found);
                    }
                }
            }
            _ => {}
        }
    }
    found
}

/// The rows of an N x 3 array held contiguously (the Tin's own arrays are).
fn rows<T>(flat: &[T]) -> &[[T; 3]] {
    flat.as_chunks::<3>().0
}

/// `crs` as WKT text and EPSG code: an int is an EPSG code, "EPSG:n" names one, any other
/// text is WKT.
pub fn crs_of(crs: Option<&Bound<'_, PyAny>>) -> PyResult<(Option<String>, Option<u32>)> {
    let Some(crs) = crs.filter(|c| !c.is_none()) else {
        return Ok((None, None));
    };
    if crs.is_instance_of::<PyInt>() {
        let code: u32 = crs.extract()?;
        return Ok((Some(format!("EPSG:{code}")), Some(code)));
    }
    if crs.is_instance_of::<PyString>() {
        let text: String = crs.extract()?;
        let epsg = match text.trim().strip_prefix("EPSG:") {
            Some(n) => n.parse().ok(),
            None => wkt_epsg(&text),
        };
        return Ok((Some(text), epsg));
    }
    // pyproj.CRS and rasterio.crs.CRS: their WKT.
    if let Ok(wkt) = crs.call_method0("to_wkt") {
        let text: String = wkt.extract()?;
        let epsg = crs
            .call_method0("to_epsg")
            .ok()
            .and_then(|e| e.extract::<Option<u32>>().ok().flatten());
        return Ok((Some(text), epsg));
    }
    Err(PyValueError::new_err(
        "crs must be WKT text, \"EPSG:n\", an EPSG code or an object with to_wkt()",
    ))
}
