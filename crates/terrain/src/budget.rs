//! Each level's error budget: its bound from `--quality`, and the height quantum its tiles
//! store heights in.

use crate::quantized_mesh::QUANTIZED_MAX;
use crate::tms::max_edge_length;

/// Cesium's level-zero geometric error for the geographic scheme, in metres:
/// `maximumRadius * 2 pi * 0.25 / (65 * 2)` (`TerrainProvider`
/// `getEstimatedLevelZeroGeometricErrorForAHeightmap`). Level L allows `e0 / 2^L`.
pub const LEVEL_ZERO_ERROR: f64 = 77_067.339_771_939_23;

/// The smallest height quantum (2^-8 m), so that tile minima stay exact in float32.
const MIN_HEIGHT_STEP: f64 = 1.0 / 256.0;

/// The level's bound and its height quantum.
#[derive(Debug, Clone, Copy)]
pub(super) struct LevelBudget {
    /// The bound asked for, `quality x e(level)`.
    pub(super) bound: f64,
    /// The height quantum.
    pub(super) step: f64,
    /// Longest edge, in lattice spacings (see [`max_edge_length`]).
    pub(super) max_edge: Option<u32>,
    /// What decimation may use: the bound less the quantization error (half a step).
    pub(super) decimation: f64,
    /// What the verifier checks: the bound, or half a step (and a margin) when larger.
    pub(super) verify: f64,
    /// The finest level's largest |height| (every level's rounding slack).
    pub(super) max_abs: f64,
}

/// How many 16-bit height quanta a tile gives each height step: the largest power of two
/// up to 2^14 that keeps `top` steps (its highest vertex above its minimum, `k_min`
/// steps above 0) within 32767 quanta, and its maximum height exact in float32
/// (`k_min * quanta + 32767` below 2^24 in magnitude). The header's maximum, the top of
/// the 16-bit range, is then within twice the tile's own height range (plus a step) instead
/// of 32767 steps up, which the level's widest tile sets; CesiumJS builds each tile's
/// bounding box from it. Heights stay multiples of the step, exactly, as neighbours
/// decode them.
pub(super) fn quanta_per_step(k_min: f64, top: f64) -> u32 {
    let mut quanta = 1u32;
    while quanta < 1 << 14
        && top * f64::from(2 * quanta) <= f64::from(QUANTIZED_MAX)
        && k_min.abs() * f64::from(2 * quanta) + f64::from(QUANTIZED_MAX) < f64::from(1u32 << 24)
    {
        quanta *= 2;
    }
    quanta
}

/// The level's bound and height quantum, from its widest tile and the finest level's
/// largest |height|.
pub(super) fn level_budget(level: u8, widest: f64, quality: f64, max_abs: f64) -> LevelBudget {
    // The height quantum: the smallest power of two that fits every tile's range in
    // 32766 steps (so a minimum rounded down to the lattice still leaves room).
    let mut height_step = MIN_HEIGHT_STEP;
    while height_step * f64::from(QUANTIZED_MAX - 1) < widest {
        height_step *= 2.0;
    }
    let bound = quality * LEVEL_ZERO_ERROR / (1u64 << level) as f64;
    let half_step = height_step / 2.0;
    // The quantization error is at most half a step; keep a relative margin of 2^-30 for
    // the float arithmetic of interpolation.
    let margin = (bound + max_abs) / (1u64 << 30) as f64;
    LevelBudget {
        bound,
        step: height_step,
        max_edge: max_edge_length(level, bound),
        decimation: (bound - half_step - margin).max(0.0),
        verify: bound.max(half_step + margin),
        max_abs,
    }
}
