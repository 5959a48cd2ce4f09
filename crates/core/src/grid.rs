//! A rectangular grid of scalar samples; NaN marks a sample outside the domain.

use crate::{Error, Result};

/// A `width` x `height` grid of samples in row-major order (row 0 first).
///
/// Sample `(x, y)` (column, row) sits at integer position `(x, y)`. A sample is *valid* when
/// it is finite; NaN and infinities mark nodata. A *cell* is the unit square with corners
/// `(x, y)`..`(x + 1, y + 1)`; it belongs to the domain when its four corners are valid.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    width: u32,
    height: u32,
    values: Vec<f64>,
    /// Largest absolute valid value (0 without valid samples).
    max_abs: f64,
    /// See [`Grid::integral_heights`].
    integral_heights: bool,
}

/// `width x height x max|value|` below this keeps an integer grid's plane arithmetic exact
/// in `f64` (see [`Grid::integral_heights`]).
const INTEGRAL_PRODUCT_LIMIT: f64 = (1u64 << 50) as f64;

impl Grid {
    /// Wraps row-major `values`; fails if `values.len() != width * height`, if either
    /// dimension is zero, or if the grid has 2^32 samples or more.
    pub fn new(width: u32, height: u32, values: Vec<f64>) -> Result<Grid> {
        let expected = width as usize * height as usize;
        if width == 0 || height == 0 || values.len() != expected {
            return Err(Error::GridSize {
                width,
                height,
                expected,
                actual: values.len(),
            });
        }
        if expected as u64 >= u32::MAX as u64 {
            return Err(Error::GridTooLarge { width, height });
        }
        let (max_abs, integers) = values
            .iter()
            .filter(|v| v.is_finite())
            .fold((0.0f64, true), |(m, integers), v| {
                (m.max(v.abs()), integers && v.fract() == 0.0)
            });
        let integral_heights = integers && Grid::integral_product_fits(width, height, max_abs);
        Ok(Grid {
            width,
            height,
            values,
            max_abs,
            integral_heights,
        })
    }

    /// Whether a grid of `width x height` integer samples up to `max_abs` in magnitude is
    /// small enough for [`Grid::integral_heights`]: `width x height x max(max_abs, 1)` is
    /// below 2^50. (Tiles of one raster use it to decide the same for all of them.)
    pub fn integral_product_fits(width: u32, height: u32, max_abs: f64) -> bool {
        f64::from(width) * f64::from(height) * max_abs.max(1.0) < INTEGRAL_PRODUCT_LIMIT
    }

    /// Whether every valid sample is an integer and `width x height x max|value|` is below
    /// 2^50. Then whether a sample lies on the plane through three others is decided
    /// exactly by an integer determinant, and a verifier interpolating such a plane in
    /// `f64` with integer barycentric weights gets the sample exactly: an error of exactly
    /// 0 can be promised and checked (integer DEMs at `max_error` 0).
    pub fn integral_heights(&self) -> bool {
        self.integral_heights
    }

    /// Number of columns.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Number of rows.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All samples, row-major; nodata samples are non-finite.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value at column `x`, row `y`, or `None` when it is nodata or out of range.
    pub fn get(&self, x: u32, y: u32) -> Option<f64> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let v = self.values[y as usize * self.width as usize + x as usize];
        v.is_finite().then_some(v)
    }

    /// Number of valid (finite) samples.
    pub fn valid_count(&self) -> usize {
        self.values.iter().filter(|v| v.is_finite()).count()
    }

    /// Number of cells whose four corners are valid: the domain's area in cell units.
    pub fn valid_cell_count(&self) -> usize {
        let w = self.width as usize;
        let mut n = 0;
        for y in 0..self.height as usize - 1 {
            for x in 0..w - 1 {
                if self.cell_is_valid(x, y) {
                    n += 1;
                }
            }
        }
        n
    }

    /// Number of samples that are a corner of at least one valid cell: the vertices of
    /// the full mesh.
    pub fn domain_sample_count(&self) -> usize {
        let (w, h) = (self.width as usize, self.height as usize);
        let cell = |x: usize, y: usize| x < w - 1 && y < h - 1 && self.cell_is_valid(x, y);
        let mut n = 0;
        for y in 0..h {
            for x in 0..w {
                let around = cell(x, y)
                    || (x > 0 && cell(x - 1, y))
                    || (y > 0 && cell(x, y - 1))
                    || (x > 0 && y > 0 && cell(x - 1, y - 1));
                n += usize::from(around);
            }
        }
        n
    }

    pub(crate) fn cell_is_valid(&self, x: usize, y: usize) -> bool {
        let w = self.width as usize;
        let i = y * w + x;
        self.values[i].is_finite()
            && self.values[i + 1].is_finite()
            && self.values[i + w].is_finite()
            && self.values[i + w + 1].is_finite()
    }

    /// Largest absolute valid value (0 for a grid without valid samples).
    pub(crate) fn max_abs_value(&self) -> f64 {
        self.max_abs
    }
}
