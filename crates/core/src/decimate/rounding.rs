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
/// data whose largest |value| is `max_abs_value`: 2^16 rounding slacks (2^-24 of `max_error
/// + max_abs_value`), at most the enforced bound over [`RAISED_HEIGHT_SHARE`] and at most
/// [`MAX_ABS_HEIGHT`] (a bound far beyond any height would otherwise lift the vertices out
/// of the range where errors fit in `f32`).
///
/// The raise only has to lift a sample exactly the bound above its triangle's plane (ties
/// on integer heights) clear of the slack, which the rounding of any verifier stays far
/// below; it gains the same from 1/64 of the bound down to 2^-20 of it (measured on
/// becmodel, Big Tujunga and a CT slice: docs/results.md). Kept small, it is invisible: a flat lake stays at its level to a
/// fraction of a millimetre, and a bound far beyond the relief does not lift the mesh.
/// It grows with `max_error`, so the raise for a bound also bounds a run's at any smaller
/// one (the float32 formats' rounding margin relies on that).
pub fn vertex_raise(max_error: f64, max_abs_value: f64) -> f64 {
    let slack = ROUNDING_SLACK * (max_error.min(f64::MAX) + max_abs_value);
    (RAISE_IN_SLACKS * slack)
        .min(effective_limit(max_error, max_abs_value) / RAISED_HEIGHT_SHARE)
        .min(MAX_ABS_HEIGHT)
}

/// The largest |height| decimation accepts: error bounds are stored as `f32`, and between
/// heights up to this they stay well within its range (and planes far from `f64` overflow).
pub const MAX_ABS_HEIGHT: f64 = 1e37;
