//! The grid being approximated: a borrowed, row-major block of samples.

/// A borrowed grid of `width * height` samples, row-major, row 0 first.
///
/// Sample `(x, y)` (column `x`, row `y`) sits at the integer position `(x, y)` and is
/// `values[y * width + x]`. A sample is *valid* iff its value is finite: NaN and ±infinity
/// mean nodata. The lengths are checked by [`verify`](crate::verify), not here.
#[derive(Debug, Clone, Copy)]
pub struct GridRef<'a> {
    /// Number of columns.
    pub width: u32,
    /// Number of rows.
    pub height: u32,
    /// `width * height` samples, row-major, row 0 first.
    pub values: &'a [f64],
}

impl<'a> GridRef<'a> {
    /// A grid of `width` columns and `height` rows over `values` (row-major, row 0 first).
    pub fn new(width: u32, height: u32, values: &'a [f64]) -> Self {
        Self {
            width,
            height,
            values,
        }
    }

    /// Number of samples, `width * height`, without overflow.
    pub(crate) fn sample_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Whether the integer position `(x, y)` is a sample of the grid.
    pub(crate) fn contains(&self, x: i64, y: i64) -> bool {
        (0..i64::from(self.width)).contains(&x) && (0..i64::from(self.height)).contains(&y)
    }

    /// Row-major index of sample `(x, y)`, which must be inside the grid.
    pub(crate) fn index(&self, x: u32, y: u32) -> usize {
        // Fits: `verify` checked that `values.len() == width * height`.
        y as usize * self.width as usize + x as usize
    }

    /// Value of sample `(x, y)`, which must be inside the grid.
    pub(crate) fn value(&self, x: u32, y: u32) -> f64 {
        self.values[self.index(x, y)]
    }

    /// Whether sample `(x, y)`, which must be inside the grid, is valid (finite).
    pub(crate) fn is_valid(&self, x: u32, y: u32) -> bool {
        self.value(x, y).is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validity_and_bounds() {
        // 3x3; (2, 1) and (2, 2) are nodata.
        #[rustfmt::skip]
        let values = [
            0.0, 1.0, 2.0,
            3.0, 4.0, f64::NAN,
            6.0, 7.0, f64::INFINITY,
        ];
        let grid = GridRef::new(3, 3, &values);
        assert!(grid.is_valid(0, 0));
        assert!(grid.is_valid(1, 2));
        assert!(!grid.is_valid(2, 1), "NaN is nodata");
        assert!(!grid.is_valid(2, 2), "infinity is nodata");
        assert_eq!(grid.value(1, 2), 7.0);
        assert_eq!(grid.index(1, 2), 7);
        assert!(grid.contains(2, 2));
        assert!(!grid.contains(3, 0));
        assert!(!grid.contains(0, -1));
        assert_eq!(grid.sample_count(), 9);
    }
}
