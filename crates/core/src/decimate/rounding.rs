//! The rounding slack kept below the requested bound, and the raise of vertex heights
//! within it.

/// Relative slack kept below the requested bound so that `f64` rounding in the bound
/// arithmetic can never let a measured error exceed `max_error` (see [`crate::decimate()`]).
const ROUNDING_SLACK: f64 = 1.0 / (1u64 << 40) as f64;

/// The bound decimation actually enforces for `max_error` on data whose largest |value| is
/// `max_abs_value`: `max_error` less a slack of `2^-40 (max_error + max_abs_value)` that
/// covers the rounding of the error arithmetic, or 0 when `max_error` is below the slack.
/// A caller that simplifies shared tile borders itself (see [`crate::decimate_with_border`])
/// keeps its 1-D errors within this limit, computed with
/// [`crate::DecimationOptions::max_abs_value`] set to the whole raster's value.
pub fn effective_limit(max_error: f64, max_abs_value: f64) -> f64 {
    let slack = ROUNDING_SLACK * (max_error.min(f64::MAX) + max_abs_value);
    if max_error > slack {
        max_error - slack
    } else {
        0.0
    }
}

/// [`crate::VertexHeights::Raised`] raises a vertex by at most the enforced bound over this (so
/// by less than `max_error / RAISED_HEIGHT_SHARE`; below that, a hair: 2^-24 of the bound
/// plus the largest |height|).
pub const RAISED_HEIGHT_SHARE: f64 = 64.0;

/// How many rounding slacks of [`effective_limit`] a raised vertex sits above its sample
/// (when that is below the bound over [`RAISED_HEIGHT_SHARE`]).
const RAISE_IN_SLACKS: f64 = 65536.0;

/// How far [`crate::VertexHeights::Raised`] puts a vertex above its sample for `max_error` on
/// data whose largest |value| is `max_abs_value`: 2^16 rounding slacks (2^-24 of
/// `max_error + max_abs_value`), at most the enforced bound over [`RAISED_HEIGHT_SHARE`],
/// and whatever the bound never more than the raise for a bound of `2 max_abs_value`: a
/// hair relative to the data (2^-24 of three times its largest |value|), nor than
/// [`MAX_ABS_HEIGHT`].
///
/// The raise only has to lift a sample exactly the bound above its triangle's plane (ties
/// on integer heights) clear of the slack, which the rounding of any verifier stays far
/// below; it gains the same from 1/64 of the bound down to 2^-20 of it (measured on
/// becmodel, Big Tujunga and a CT slice: docs/results.md). Kept small, it is invisible: a
/// flat lake stays at its level to a fraction of a millimetre, and a bound far beyond the
/// relief does not lift the mesh. No sample is more than `2 max_abs_value` from a plane
/// through samples, so beyond that bound there is no tie to lift (uncapped,
/// `--max-error 1e308` raised vertices on heights below 50 to 6e300). It grows with
/// `max_error` up to the cap, so the raise for a bound also bounds a run's at any smaller
/// one (the float32 formats' rounding margin relies on that).
pub fn vertex_raise(max_error: f64, max_abs_value: f64) -> f64 {
    let bound = max_error.min(2.0 * max_abs_value);
    let slack = ROUNDING_SLACK * (bound + max_abs_value);
    (RAISE_IN_SLACKS * slack)
        .min(effective_limit(max_error, max_abs_value) / RAISED_HEIGHT_SHARE)
        .min(MAX_ABS_HEIGHT)
}

/// The largest |height| decimation accepts: error bounds are stored as `f32`, and between
/// heights up to this they stay well within its range (and planes far from `f64` overflow).
pub const MAX_ABS_HEIGHT: f64 = 1e37;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_huge_bound_raises_vertices_by_a_hair_of_the_data() {
        // Heights of at most 547 (becmodel): the raise stays below a millimetre whatever
        // the bound, and is the raise of small bounds unchanged.
        for bound in [1e3, 1e6, 1e46, 1e308, f64::MAX] {
            let raise = vertex_raise(bound, 547.0);
            assert!(raise > 0.0 && raise < 1e-3, "{bound}: raised by {raise}");
        }
        assert_eq!(vertex_raise(1.0, 547.0), 548.0 * 2f64.powi(-24));
        // Never smaller for a larger bound.
        let bounds = [0.0, 1e-9, 0.5, 1.0, 100.0, 1094.0, 1095.0, 1e9, 1e308];
        for pair in bounds.windows(2) {
            assert!(
                vertex_raise(pair[0], 547.0) <= vertex_raise(pair[1], 547.0),
                "{pair:?}"
            );
        }
        // Flat data at 0 has no tie to lift.
        assert_eq!(vertex_raise(1e308, 0.0), 0.0);
    }
}
