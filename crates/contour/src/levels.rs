//! Choosing contour levels: a regular interval with an offset, or an explicit list.

use crate::{Error, Result};

/// The most levels [`interval_levels`] will produce (a guard against a tiny interval).
pub const MAX_LEVELS: usize = 100_000;

/// The levels `offset + k * interval` (integer `k`) that lie in `min..=max`, ascending.
///
/// Each level is computed as `offset + k as f64 * interval`, not by repeated addition, so
/// levels do not drift (the same rule as `gdal_contour -i`). A level equal to `min` is
/// included; it produces no line, since contours separate samples below the level from
/// samples at or above it.
///
/// # Errors
/// [`Error::InvalidInterval`] unless `interval` is finite and `> 0` and `offset` finite;
/// [`Error::TooManyLevels`] beyond [`MAX_LEVELS`]. `min > max` or non-finite bounds give
/// no levels.
///
/// # Example
/// ```
/// let levels = tinsmith_contour::interval_levels(10.0, 5.0, 12.0, 41.0)?;
/// assert_eq!(levels, [15.0, 25.0, 35.0]);
/// # Ok::<(), tinsmith_contour::Error>(())
/// ```
pub fn interval_levels(interval: f64, offset: f64, min: f64, max: f64) -> Result<Vec<f64>> {
    if !(interval.is_finite() && interval > 0.0 && offset.is_finite()) {
        return Err(Error::InvalidInterval { interval, offset });
    }
    if !(min.is_finite() && max.is_finite() && min <= max) {
        return Ok(Vec::new());
    }
    let first = ((min - offset) / interval).ceil();
    let last = ((max - offset) / interval).floor();
    let count = last - first + 1.0;
    if count.is_nan() || count > MAX_LEVELS as f64 {
        return Err(Error::TooManyLevels {
            interval,
            min,
            max,
            count,
            max_levels: MAX_LEVELS,
        });
    }
    // Every k must be an exact integer in f64, and neighbouring levels distinct.
    let below_resolution = Error::IntervalBelowResolution {
        interval,
        offset,
        min,
        max,
    };
    const EXACT_INTEGERS: f64 = (1u64 << 53) as f64;
    if first.abs() + 1.0 >= EXACT_INTEGERS || last.abs() + 1.0 >= EXACT_INTEGERS {
        return Err(below_resolution);
    }
    let mut levels: Vec<f64> = Vec::new();
    // One step past each end, filtered by value, absorbs rounding in `first` and `last`.
    let steps = (last - first) as i64 + 3;
    for i in 0..steps.max(0) {
        let k = first - 1.0 + i as f64;
        let level = offset + k * interval;
        if (min..=max).contains(&level) {
            // Neighbours must stay apart, and each level at `offset + k * interval` to
            // within a thousandth of the interval (an offset of 1e16 with an interval of 3
            // rounded levels by up to 2, unevenly).
            if levels.last().is_some_and(|&l| l >= level)
                || rounding_error(offset, k, interval).abs() > interval * MAX_LEVEL_ROUNDING
            {
                return Err(below_resolution);
            }
            levels.push(level);
        }
    }
    Ok(levels)
}

/// The largest rounding of an interval level from `offset + k * interval`, as a share of
/// the interval.
const MAX_LEVEL_ROUNDING: f64 = 1e-3;

/// How far `offset + k * interval`, computed in f64, is from its exact value (to within
/// the rounding of this sum of errors): the product's error by a fused multiply-add, the
/// sum's by Knuth's two-sum.
fn rounding_error(offset: f64, k: f64, interval: f64) -> f64 {
    let product = k * interval;
    let product_error = k.mul_add(interval, -product);
    let sum = offset + product;
    let product_part = sum - offset;
    let sum_error = (offset - (sum - product_part)) + (product - product_part);
    product_error + sum_error
}

/// `levels` sorted ascending without duplicates (`-0.0` and `0.0` count as one).
///
/// # Errors
/// [`Error::InvalidLevel`] when a level is NaN or infinite.
pub fn sorted_levels(levels: &[f64]) -> Result<Vec<f64>> {
    if let Some(&bad) = levels.iter().find(|l| !l.is_finite()) {
        return Err(Error::InvalidLevel(bad));
    }
    // Adding 0.0 turns -0.0 into 0.0, so the two sort and dedup as one level.
    let mut sorted: Vec<f64> = levels.iter().map(|&l| l + 0.0).collect();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    Ok(sorted)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_with_offset() {
        assert_eq!(
            interval_levels(10.0, 5.0, 12.0, 41.0).unwrap(),
            [15.0, 25.0, 35.0]
        );
        assert_eq!(
            interval_levels(10.0, 0.0, 10.0, 30.0).unwrap(),
            [10.0, 20.0, 30.0]
        );
        assert_eq!(
            interval_levels(0.5, 0.0, -1.2, 0.3).unwrap(),
            [-1.0, -0.5, 0.0]
        );
        assert!(interval_levels(10.0, 0.0, 1.0, 9.0).unwrap().is_empty());
        assert!(interval_levels(10.0, 0.0, f64::NAN, 9.0)
            .unwrap()
            .is_empty());
    }

    #[test]
    fn levels_are_not_accumulated() {
        let levels = interval_levels(0.1, 0.0, 0.0, 100.0).unwrap();
        assert_eq!(levels.len(), 1001);
        assert_eq!(levels[1000], 1000.0 * 0.1);
        assert_eq!(levels[3], 3.0 * 0.1);
    }

    #[test]
    fn bad_intervals_and_too_many_levels() {
        for (i, o) in [
            (0.0, 0.0),
            (-1.0, 0.0),
            (f64::NAN, 0.0),
            (1.0, f64::INFINITY),
        ] {
            assert!(matches!(
                interval_levels(i, o, 0.0, 1.0),
                Err(Error::InvalidInterval { .. })
            ));
        }
        assert!(matches!(
            interval_levels(1e-6, 0.0, 0.0, 1000.0),
            Err(Error::TooManyLevels { .. })
        ));
    }

    #[test]
    fn levels_closer_than_f64_resolution_are_refused() {
        // Heights near 1e18 (f64 spacing 128) with an interval of 50, and an offset so far
        // from the heights that k passes 2^53: both used to loop forever.
        for (interval, offset, min, max) in [
            (50.0, 0.0, 1e18, 1e18 + 4e6),
            (10.0, 1e17, 388.0, 3863.0),
            (1.0, 0.0, 2f64.powi(53), 2f64.powi(53) + 100.0),
            // k below 2^53, but offset + k * 3 rounded to even numbers near 1e16.
            (3.0, 1e16, 140.0, 400.0),
        ] {
            assert!(
                matches!(
                    interval_levels(interval, offset, min, max),
                    Err(Error::IntervalBelowResolution { .. })
                ),
                "{interval} {offset} {min} {max}"
            );
        }
        // Large but resolvable: fine.
        let levels = interval_levels(1024.0, 0.0, 1e15, 1e15 + 10_240.0).unwrap();
        assert_eq!(levels.len(), 11);
        let levels = interval_levels(3.0, 1e15 + 1.0, 140.0, 150.0).unwrap();
        assert_eq!(levels, [140.0, 143.0, 146.0, 149.0]);
        // Decimal steps round by an ulp, far below the interval: fine.
        let levels = interval_levels(0.1, 0.3, 0.05, 0.95).unwrap();
        assert_eq!(levels.len(), 9, "{levels:?}");
        let levels = interval_levels(1e-5, 0.0, 1e6, 1e6 + 1e-3).unwrap();
        assert!((100..=102).contains(&levels.len()), "{}", levels.len());
    }

    #[test]
    fn explicit_levels_sorted_and_checked() {
        assert_eq!(
            sorted_levels(&[3.0, 1.0, 3.0, -0.0, 0.0]).unwrap(),
            [0.0, 1.0, 3.0]
        );
        assert!(matches!(
            sorted_levels(&[1.0, f64::NAN]),
            Err(Error::InvalidLevel(_))
        ));
    }
}
