//! The local origin of the float32 formats (STL, glTF): world = origin + f32 offset.

/// Significant decimal digits kept in an origin chosen by [`LocalOrigin::around`], so that
/// it prints short (it goes into the 80-byte STL header) and reads back exactly.
const ORIGIN_DIGITS: usize = 7;

/// A translation that float32 formats store positions relative to.
///
/// Float32 has 24 significant bits: at UTM magnitudes (10^6 m) that is a step of 0.06 m,
/// too coarse for a TIN whose error is guaranteed. Relative to an origin in the middle of
/// the data, a 10 km extent keeps steps below 0.001 m. The writers store
/// `f32(p - origin)` and the readers give back `origin + f64(stored)`, computed exactly as
/// [`LocalOrigin::quantize`] does, so a caller can know before writing which coordinates
/// (and heights) the file will hold.
///
/// # Example
/// ```
/// use tinsmith_formats::LocalOrigin;
/// let origin = LocalOrigin::around([500_000.0, 5_200_000.0, 300.0], [520_000.0, 5_230_000.0, 2_100.0]);
/// assert_eq!(origin.offset(), [510_000.0, 5_215_000.0, 1_200.0]);
/// let p = [512_345.678, 5_213_210.123, 1_234.567];
/// let q = origin.quantize(p);
/// assert!((q[0] - p[0]).abs() < 1e-3 && (q[2] - p[2]).abs() < 1e-4);
/// assert_eq!(origin.quantize(q), q, "quantized points are fixed points");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalOrigin {
    offset: [f64; 3],
}

impl LocalOrigin {
    /// An origin at `offset` exactly. Non-finite components are replaced by 0.
    pub fn new(offset: [f64; 3]) -> LocalOrigin {
        LocalOrigin {
            offset: offset.map(|c| if c.is_finite() { c } else { 0.0 }),
        }
    }

    /// The centre of the box `min..=max`, rounded to 7 significant digits (a few units at
    /// UTM magnitudes, far less than the extent, so the float32 steps stay as fine as the
    /// centre would give, and the origin prints short). Non-finite components give 0.
    pub fn around(min: [f64; 3], max: [f64; 3]) -> LocalOrigin {
        let mut offset = [0.0; 3];
        for axis in 0..3 {
            let centre = min[axis] / 2.0 + max[axis] / 2.0;
            offset[axis] = round_significant(centre, ORIGIN_DIGITS);
        }
        LocalOrigin::new(offset)
    }

    /// The origin of the bounding box of `points` (see [`LocalOrigin::around`]); the zero
    /// origin for no points.
    pub fn of_points(points: &[[f64; 3]]) -> LocalOrigin {
        let Some(first) = points.first() else {
            return LocalOrigin::new([0.0; 3]);
        };
        let (mut min, mut max) = (*first, *first);
        for p in points {
            for axis in 0..3 {
                min[axis] = min[axis].min(p[axis]);
                max[axis] = max[axis].max(p[axis]);
            }
        }
        LocalOrigin::around(min, max)
    }

    /// The origin's world coordinates.
    pub fn offset(&self) -> [f64; 3] {
        self.offset
    }

    /// `p` relative to the origin, rounded to float32 (to nearest), as the files store it.
    pub fn to_local(&self, p: [f64; 3]) -> [f32; 3] {
        [0, 1, 2].map(|axis| (p[axis] - self.offset[axis]) as f32)
    }

    /// The world position of a stored offset: `origin + f64(local)`, as the readers
    /// compute it.
    pub fn to_world(&self, local: [f32; 3]) -> [f64; 3] {
        [0, 1, 2].map(|axis| self.offset[axis] + f64::from(local[axis]))
    }

    /// The position a float32 file gives back for `p`: `to_world(to_local(p))`.
    pub fn quantize(&self, p: [f64; 3]) -> [f64; 3] {
        self.to_world(self.to_local(p))
    }

    /// The largest |stored - z| over the finite `heights`, each stored as the file stores
    /// it ([`LocalOrigin::quantize`]): the exact height rounding of a mesh whose vertices
    /// are among those heights.
    pub fn height_rounding(&self, heights: &[f64]) -> f64 {
        heights
            .iter()
            .filter(|z| z.is_finite())
            .map(|&z| (self.quantize([0.0, 0.0, z])[2] - z).abs())
            .fold(0.0, f64::max)
    }

    /// An upper bound on |stored - z| for every height `z` in `[min, max]`: half a float32
    /// step of the largest offset (2^-24 of it), plus the `f64` roundings of the
    /// subtraction and the addition back, with a factor 2 to spare.
    pub fn height_rounding_bound(&self, min: f64, max: f64) -> f64 {
        let oz = self.offset[2];
        let offset = (max - oz).abs().max((min - oz).abs());
        let magnitude = max.abs().max(min.abs());
        2.0 * (offset * 2f64.powi(-24) + (offset + magnitude) * 2f64.powi(-52))
    }
}

/// `value` rounded to `digits` significant decimal digits (through its decimal text, so
/// the result is the `f64` nearest to a short decimal).
fn round_significant(value: f64, digits: usize) -> f64 {
    if !value.is_finite() || value == 0.0 {
        return 0.0;
    }
    let text = format!("{:.*e}", digits.saturating_sub(1), value);
    text.parse().unwrap_or(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn around_rounds_the_centre_to_short_decimals() {
        let origin = LocalOrigin::around([0.0, -10.0, 1.0], [99.0, 10.0, 2.0]);
        assert_eq!(origin.offset(), [49.5, 0.0, 1.5]);
        let origin = LocalOrigin::around(
            [1_234_567.891_234, 0.000_123_456_789, 0.0],
            [1_234_567.891_234, 0.000_123_456_789, 0.0],
        );
        assert_eq!(origin.offset(), [1_234_568.0, 0.000_123_456_8, 0.0]);
        for c in origin.offset() {
            assert!(format!("{c:?}").len() <= 14, "{c:?}");
        }
    }

    #[test]
    fn non_finite_inputs_give_zero() {
        let origin = LocalOrigin::around([f64::NAN, f64::MAX, -f64::MAX], [1.0, f64::MAX, 0.0]);
        assert_eq!(origin.offset()[0], 0.0);
        assert!(origin.offset()[1].is_finite());
        assert_eq!(
            LocalOrigin::new([f64::INFINITY, 1.0, 2.0]).offset(),
            [0.0, 1.0, 2.0]
        );
    }

    #[test]
    fn quantize_is_close_and_idempotent_at_utm_magnitudes() {
        let points = [
            [500_000.0, 4_649_776.0, 312.5],
            [510_000.25, 4_659_776.75, 2_962.125],
        ];
        let origin = LocalOrigin::of_points(&points);
        for p in points {
            let q = origin.quantize(p);
            for axis in 0..3 {
                // Half a float32 step at 8192 is 2^-11.
                assert!((q[axis] - p[axis]).abs() <= 2f64.powi(-11), "{p:?} {q:?}");
            }
            assert_eq!(origin.quantize(q), q);
        }
    }

    #[test]
    fn of_no_points_is_zero() {
        assert_eq!(LocalOrigin::of_points(&[]).offset(), [0.0; 3]);
    }
}
