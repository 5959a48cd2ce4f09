//! A rectangle of raster samples as plain data: what ingestion hands out.

use std::sync::Arc;

/// A `width` x `height` block of samples: `values` in row-major order (row 0 first, then
/// row 1, ...), so sample `(x, y)` (column, row) is `values[y * width + x]`.
///
/// NaN marks nodata; a raster reader hands out every other sample finite (any non-finite
/// value is nodata to every consumer). [`Samples::new`] guarantees that both dimensions
/// are at least 1, that there are exactly `width * height` values, and that there are
/// fewer than 2^32 - 1 of them (so every sample has a `u32` index). Nothing else is
/// computed or cached: building the decimator's grid from it is the core's business.
///
/// The values are owned ([`Samples::new`]) or shared with their owner
/// ([`Samples::shared`], e.g. a numpy array read in place); either way they never change
/// while a `Samples` holds them.
#[derive(Clone)]
pub struct Samples {
    width: u32,
    height: u32,
    values: Values,
}

/// Where the values of [`Samples`] live.
#[derive(Clone)]
enum Values {
    Owned(Vec<f64>),
    Shared(Arc<dyn AsRef<[f64]> + Send + Sync>),
}

impl std::fmt::Debug for Samples {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Samples")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("shared", &matches!(self.values, Values::Shared(_)))
            .finish_non_exhaustive()
    }
}

/// Equal when the sizes and the values are equal, nodata (NaN) equal to nodata, however
/// they are held.
impl PartialEq for Samples {
    fn eq(&self, other: &Samples) -> bool {
        self.width == other.width
            && self.height == other.height
            && self.values().len() == other.values().len()
            && self
                .values()
                .iter()
                .zip(other.values())
                .all(|(a, b)| a == b || (a.is_nan() && b.is_nan()))
    }
}

/// Why [`Samples::new`] refused its values; the messages name the grid the values were to
/// form.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SamplesError {
    /// The dimensions and the value count disagree, or a dimension is zero.
    #[error("grid of {width}x{height} needs {expected} values, got {actual}")]
    Size {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// width * height.
        expected: usize,
        /// Values supplied.
        actual: usize,
    },
    /// Too many samples to index with 32 bits (2^32 - 1 or more).
    #[error("grid of {width}x{height} has more than 2^32-1 samples")]
    TooLarge {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
    },
}

impl Samples {
    /// Wraps row-major `values` (NaN = nodata); fails if `values.len() != width * height`,
    /// if either dimension is zero ([`SamplesError::Size`]), or if there are 2^32 - 1
    /// samples or more ([`SamplesError::TooLarge`]).
    pub fn new(width: u32, height: u32, values: Vec<f64>) -> Result<Samples, SamplesError> {
        check_size(width, height, values.len())?;
        Ok(Samples {
            width,
            height,
            values: Values::Owned(values),
        })
    }

    /// Samples read where `values` holds them, without a copy: the same checks as
    /// [`Samples::new`]. The holder must keep its slice unchanged for as long as any
    /// `Samples` (or a clone) refers to it, and must hold every nodata sample as NaN or
    /// another non-finite value, each of which is nodata here.
    pub fn shared(
        width: u32,
        height: u32,
        values: Arc<dyn AsRef<[f64]> + Send + Sync>,
    ) -> Result<Samples, SamplesError> {
        check_size(width, height, (*values).as_ref().len())?;
        Ok(Samples {
            width,
            height,
            values: Values::Shared(values),
        })
    }

    /// Whether the values are shared with their owner ([`Samples::shared`]) rather than
    /// owned.
    pub fn is_shared(&self) -> bool {
        matches!(self.values, Values::Shared(_))
    }

    /// Number of columns (at least 1).
    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Number of rows (at least 1).
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All `width * height` samples, row-major; nodata samples are NaN (non-finite).
    #[inline]
    pub fn values(&self) -> &[f64] {
        match &self.values {
            Values::Owned(values) => values,
            Values::Shared(values) => (**values).as_ref(),
        }
    }

    /// The value at column `x`, row `y`, or `None` when it is nodata or out of range.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Option<f64> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let v = self.values()[y as usize * self.width as usize + x as usize];
        v.is_finite().then_some(v)
    }

    /// Number of valid (finite) samples.
    pub fn valid_count(&self) -> usize {
        self.values().iter().filter(|v| v.is_finite()).count()
    }

    /// Number of cells whose four corners are valid: the area, in cells, that a TIN of
    /// these samples can cover.
    pub fn valid_cell_count(&self) -> usize {
        let (w, h) = (self.width as usize, self.height as usize);
        if self.all_valid() {
            // One pass that vectorises, instead of four loads a cell: most DEM tiles have
            // no nodata, and the decimator asks often.
            return (w - 1) * (h - 1);
        }
        (0..h - 1)
            .map(|y| (0..w - 1).filter(|&x| self.cell_is_valid(x, y)).count())
            .sum()
    }

    /// Whether every sample is valid (finite).
    pub fn all_valid(&self) -> bool {
        // Chunks without an early exit inside vectorise: the callers ask once per tile of
        // tens of thousands of samples, and most tiles have no nodata.
        self.values()
            .chunks(256)
            .all(|chunk| chunk.iter().fold(true, |all, v| all & v.is_finite()))
    }

    /// Whether the cell with top-left sample `(x, y)` has four valid corners. Panics when
    /// the cell is not inside the grid (`x + 1 < width`, `y + 1 < height`).
    #[inline]
    pub fn cell_is_valid(&self, x: usize, y: usize) -> bool {
        let w = self.width as usize;
        let i = y * w + x;
        let values = self.values();
        values[i].is_finite()
            && values[i + 1].is_finite()
            && values[i + w].is_finite()
            && values[i + w + 1].is_finite()
    }
}

/// Refuses a `width` x `height` grid of `count` values as [`Samples::new`] documents.
fn check_size(width: u32, height: u32, count: usize) -> Result<(), SamplesError> {
    let expected = width as usize * height as usize;
    if width == 0 || height == 0 || count != expected {
        return Err(SamplesError::Size {
            width,
            height,
            expected,
            actual: count,
        });
    }
    if expected as u64 >= u32::MAX as u64 {
        return Err(SamplesError::TooLarge { width, height });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked_as_the_core_checks_them() {
        assert_eq!(
            Samples::new(2, 3, vec![0.0; 5]).unwrap_err().to_string(),
            "grid of 2x3 needs 6 values, got 5"
        );
        assert!(matches!(
            Samples::new(0, 3, Vec::new()),
            Err(SamplesError::Size { expected: 0, .. })
        ));
        assert_eq!(
            SamplesError::TooLarge {
                width: 65536,
                height: 65536
            }
            .to_string(),
            "grid of 65536x65536 has more than 2^32-1 samples"
        );
    }

    #[test]
    fn shared_values_are_read_in_place_and_compare_as_owned_ones() {
        let values: Arc<Vec<f64>> = Arc::new(vec![1.0, 2.0, f64::NAN, 4.0]);
        let shared = Samples::shared(2, 2, values.clone()).unwrap();
        assert!(shared.is_shared());
        assert_eq!(shared.values().as_ptr(), values.as_ptr());
        let owned = Samples::new(2, 2, vec![1.0, 2.0, f64::NAN, 4.0]).unwrap();
        assert!(!owned.is_shared());
        assert_eq!(shared, owned);
        assert_ne!(
            shared,
            Samples::new(2, 2, vec![1.0, 2.0, 3.0, 4.0]).unwrap()
        );
        assert!(Samples::shared(3, 2, values).is_err());
    }

    #[test]
    fn nodata_is_not_valid_and_breaks_cells() {
        let nan = f64::NAN;
        let s = Samples::new(3, 2, vec![1.0, 2.0, 3.0, 4.0, nan, 6.0]).unwrap();
        assert_eq!(s.valid_count(), 5);
        assert_eq!(s.valid_cell_count(), 0);
        assert_eq!(s.get(2, 1), Some(6.0));
        assert_eq!(s.get(1, 1), None);
        assert_eq!(s.get(3, 0), None);
        let s = Samples::new(3, 2, vec![1.0, 2.0, 3.0, 4.0, 5.0, nan]).unwrap();
        assert_eq!(s.valid_cell_count(), 1);
        assert!(s.cell_is_valid(0, 0) && !s.cell_is_valid(1, 0));
    }
}
