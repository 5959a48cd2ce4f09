//! A 2D numpy array of any numeric dtype as the samples the decimator reads: a C-ordered
//! `float64` array with no nodata value, no mask and no infinities is read in place (no
//! copy); any other array is read once, in a single pass over it as it lies in memory (any
//! strides), into one `f64` grid, nodata and masked-out samples made NaN.

use std::sync::Arc;

use numpy::ndarray::ArrayView2;
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use tinsmith_georef::Samples;

/// A sample type the binding reads without converting the array first.
trait Sample: numpy::Element + Copy {
    fn to_f64(self) -> f64;
    /// Whether the sample is `nodata`, compared in the array's own type (as the raster
    /// reader compares a band's nodata value), so a float32 array's -3.4e38 matches the
    /// nodata value given as a Python float.
    fn is_nodata(self, nodata: f64) -> bool;
}

macro_rules! exact_sample {
    ($($t:ty),*) => {$(
        impl Sample for $t {
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn is_nodata(self, nodata: f64) -> bool {
                self as f64 == nodata
            }
        }
    )*};
}
exact_sample!(f64, i8, i16, i32, i64, u8, u16, u32, u64);

impl Sample for f32 {
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn is_nodata(self, nodata: f64) -> bool {
        self == nodata as f32
    }
}

/// Fails before any allocation when `width` x `height` samples held at `bytes_per_sample`
/// (plus `extra` bytes) would not fit in the memory this process may still take
/// (`tinsmith_tiling::available_bytes`); `what` names the work.
pub fn check_fits(
    width: u64,
    height: u64,
    bytes_per_sample: u64,
    extra: u64,
    what: &str,
) -> PyResult<()> {
    let needed = (width * height)
        .saturating_mul(bytes_per_sample)
        .saturating_add(extra);
    match tinsmith_tiling::available_bytes() {
        Some(available) if needed > available => Err(PyMemoryError::new_err(format!(
            "{what} a {width}x{height} array needs about {:.1} GB, and {:.1} GB is available; \
             give max_error with a smaller tile_size, or a smaller array",
            needed as f64 / 1e9,
            available as f64 / 1e9
        ))),
        _ => Ok(()),
    }
}

/// The (rows, columns) of a 2D array, refusing arrays with fewer than two of either: they
/// have no cell to triangulate.
pub fn shape(array: &Bound<'_, PyAny>) -> PyResult<(usize, usize)> {
    let array = array
        .cast::<numpy::PyUntypedArray>()
        .map_err(|_| PyTypeError::new_err("heights must be a numpy array"))?;
    if array.ndim() != 2 {
        return Err(PyValueError::new_err(format!(
            "heights must be a 2D array (rows, columns), got {} dimensions",
            array.ndim()
        )));
    }
    let (rows, columns) = (array.shape()[0], array.shape()[1]);
    if rows < 2 || columns < 2 {
        return Err(PyValueError::new_err(format!(
            "a {columns}x{rows} array (columns x rows) has no 2x2 block of samples to \
             triangulate: heights need at least 2 rows and 2 columns"
        )));
    }
    if (rows as u64) * (columns as u64) >= u64::from(u32::MAX) || columns > u32::MAX as usize {
        return Err(PyValueError::new_err(format!(
            "a {columns}x{rows} array has 2^32 - 1 samples or more, beyond what a grid holds"
        )));
    }
    Ok((rows, columns))
}

/// Reads `array` (2D, any of the numeric dtypes numpy has but float16 and complex) as the
/// grid's samples; `mask` (same shape, `True` = valid) and `nodata` turn samples into NaN.
/// A C-ordered `float64` array without `mask`, without a finite `nodata` and without
/// infinities is read in place ([`Samples::is_shared`]); the caller must not let Python
/// write to it while the samples live (the binding drops them before it returns). The
/// caller has checked the shape ([`shape`]) and the memory ([`check_fits`]).
pub fn read(
    array: &Bound<'_, PyAny>,
    nodata: Option<f64>,
    mask: Option<&PyReadonlyArray2<'_, bool>>,
) -> PyResult<Samples> {
    if mask.is_none() && !nodata.is_some_and(f64::is_finite) {
        if let Some(samples) = in_place::samples(array)? {
            return Ok(samples);
        }
    }
    let mask = mask.map(|m| m.as_array());
    macro_rules! try_types {
        ($($t:ty),*) => {$(
            if let Ok(a) = array.cast::<PyArray2<$t>>() {
                let a = a.try_readonly()?;
                return collect(a.as_array(), nodata, mask);
            }
        )*};
    }
    try_types!(f64, f32, i16, u16, i32, u32, i8, u8, i64, u64);
    let dtype = array
        .getattr("dtype")
        .map(|d| d.to_string())
        .unwrap_or_else(|_| "unknown".into());
    Err(PyTypeError::new_err(format!(
        "heights must have a real numeric dtype (float or integer), got {dtype}"
    )))
}

fn collect<T: Sample>(
    view: ArrayView2<'_, T>,
    nodata: Option<f64>,
    mask: Option<ArrayView2<'_, bool>>,
) -> PyResult<Samples> {
    let (rows, columns) = view.dim();
    if let Some(m) = &mask {
        if m.dim() != view.dim() {
            let (mr, mc) = m.dim();
            return Err(PyValueError::new_err(format!(
                "mask has shape ({mr}, {mc}), heights ({rows}, {columns}): they must match"
            )));
        }
    }
    let mut values = Vec::with_capacity(rows * columns);
    let convert = |v: T| match nodata {
        Some(n) if v.is_nodata(n) => f64::NAN,
        _ => v.to_f64(),
    };
    match view.as_slice() {
        // Contiguous row-major: one straight pass.
        Some(slice) => values.extend(slice.iter().map(|&v| convert(v))),
        None => values.extend(view.iter().map(|&v| convert(v))),
    }
    if let Some(m) = mask {
        for (value, &valid) in values.iter_mut().zip(m.iter()) {
            if !valid {
                *value = f64::NAN;
            }
        }
    }
    // Infinities are nodata, as the raster reader has them.
    for v in values.iter_mut().filter(|v| v.is_infinite()) {
        *v = f64::NAN;
    }
    Samples::new(columns as u32, rows as u32, values)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A C-ordered `float64` array read where numpy keeps it.
#[allow(unsafe_code)]
mod in_place {
    use super::*;

    /// The values of a `float64` array, kept alive by a reference to it.
    struct ArrayValues {
        /// Holds the array (and so its buffer, which numpy neither frees nor moves while
        /// a reference exists: `resize` refuses a referenced array).
        _array: Py<PyArray2<f64>>,
        /// The first value's address and the count of values.
        start: usize,
        len: usize,
    }

    impl AsRef<[f64]> for ArrayValues {
        fn as_ref(&self) -> &[f64] {
            // SAFETY: `start` and `len` are a contiguous `f64` buffer of the array that
            // `_array` keeps alive (see `samples`); the binding reads it only during the
            // call, which does not let Python write to it (see `read`).
            unsafe { std::slice::from_raw_parts(self.start as *const f64, self.len) }
        }
    }

    /// The samples of `array` in place, when it is a C-ordered, aligned `float64` array
    /// in native byte order with no infinity (NaN is nodata as it stands); `None`
    /// otherwise.
    pub fn samples(array: &Bound<'_, PyAny>) -> PyResult<Option<Samples>> {
        let Ok(typed) = array.cast::<PyArray2<f64>>() else {
            return Ok(None);
        };
        // `as_slice` also takes Fortran order, whose memory is column-major.
        if !typed.is_c_contiguous() {
            return Ok(None);
        }
        let readonly = typed.try_readonly()?;
        let Ok(values) = readonly.as_slice() else {
            return Ok(None);
        };
        if values.iter().any(|v| v.is_infinite()) {
            return Ok(None);
        }
        let (rows, columns) = readonly.as_array().dim();
        let shared = ArrayValues {
            _array: typed.clone().unbind(),
            start: values.as_ptr() as usize,
            len: values.len(),
        };
        Samples::shared(columns as u32, rows as u32, Arc::new(shared))
            .map(Some)
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }
}
