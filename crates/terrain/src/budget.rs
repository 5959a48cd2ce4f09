//! Each level's error budget: its bound from `--quality`, the height quantum its tiles
//! store heights in, and what a tile may spend on decimation once rounding is paid for.
//!
//! Everything here depends on the level, `--quality` and the tile's (or shared edge's)
//! own samples only, never on other tiles: a tile is a function of its own data.

use crate::quantized_mesh::QUANTIZED_MAX;
use crate::tms::{max_edge_length, Scheme, Tiling};

/// Cesium's level-zero geometric error for the geographic scheme, in metres:
/// `maximumRadius * 2 pi * 0.25 / (65 * 2)` (`TerrainProvider`
/// `getEstimatedLevelZeroGeometricErrorForAHeightmap`). Level L allows `e0 / 2^L`.
pub const LEVEL_ZERO_ERROR: f64 = 77_067.339_771_939_23;

/// Cesium's level-zero geometric error of `tiling`: it divides by the level's tile
/// columns, so Web Mercator's (one column) is twice the geographic one. A Web Mercator
/// tile of level L is as wide as a geographic one of level L - 1, and allows as much.
pub(super) fn level_zero_error(tiling: Tiling) -> f64 {
    match tiling {
        Tiling::Geographic => LEVEL_ZERO_ERROR,
        Tiling::Mercator => 2.0 * LEVEL_ZERO_ERROR,
    }
}

/// The smallest height quantum (2^-8 m), so that tile minima stay exact in float32.
const MIN_HEIGHT_STEP: f64 = 1.0 / 256.0;

/// The height quantum is the largest power of two up to `bound / STEP_SHARE` (and up to
/// [`MAX_HEIGHT_STEP`]): rounding a height to it costs at most `bound / 32` of the bound,
/// and a tile can span 32766 quanta, at least `bound x 2^11` metres (a rise of about 7.9 x
/// `--quality` times the tile's width, which no terrain has) or 32766 m.
const STEP_SHARE: f64 = 16.0;

/// The largest height quantum (1 m): 32766 of them span any range of heights on Earth, from
/// the deepest trench to the highest summit, so coarse levels keep metre heights.
const MAX_HEIGHT_STEP: f64 = 1.0;

/// The smallest magnitude the rounding slacks assume: heights on Earth stay below it, so
/// a tile of lowland and one of mountains get the same slack.
const MIN_SLACK_SCALE: f64 = 16_384.0;

/// The level's bound and height quantum.
#[derive(Debug, Clone, Copy)]
pub(super) struct LevelBudget {
    /// The bound asked for, `quality x e(level)`.
    pub(super) bound: f64,
    /// The height quantum: every stored height is a multiple of it.
    pub(super) step: f64,
    /// Longest edge, in lattice spacings (see [`max_edge_length`]).
    pub(super) max_edge: Option<u32>,
}

impl LevelBudget {
    /// The budget of `level` of `tiling` at `quality`.
    pub(super) fn new(tiling: Scheme, level: u8, quality: f64) -> LevelBudget {
        let bound = quality * level_zero_error(tiling.tiling) / (1u64 << level) as f64;
        let mut step = MIN_HEIGHT_STEP;
        while step * 2.0 <= bound / STEP_SHARE && step < MAX_HEIGHT_STEP {
            step *= 2.0;
        }
        LevelBudget {
            bound,
            step,
            max_edge: max_edge_length(tiling.tiling, tiling.cells, level, bound),
        }
    }

    /// The float-arithmetic margin for heights up to `scale` in magnitude (2^-30 of
    /// bound plus scale).
    fn margin(&self, scale: f64) -> f64 {
        (self.bound + scale) / (1u64 << 30) as f64
    }

    /// What decimation may use for data up to `scale` in magnitude: the bound less the
    /// quantization error (half a step) and the margin; 0 when nothing is left.
    pub(super) fn decimation(&self, scale: f64) -> f64 {
        (self.bound - self.step / 2.0 - self.margin(scale)).max(0.0)
    }

    /// What the verifier checks: the bound, or half a step and the margin when larger.
    pub(super) fn verify(&self, scale: f64) -> f64 {
        self.bound.max(self.step / 2.0 + self.margin(scale))
    }

    /// The most quanta a tile's heights may span: 32766, so a minimum rounded down to the
    /// lattice still leaves room.
    pub(super) fn capacity(&self) -> f64 {
        f64::from(QUANTIZED_MAX - 1) * self.step
    }
}

/// The magnitude the rounding slacks of `values` assume: the next power of two above their
/// largest finite |value|, at least [`MIN_SLACK_SCALE`]. Two tiles computing it from the
/// same samples (a shared edge) get the same.
pub(super) fn slack_scale(values: impl IntoIterator<Item = f64>) -> f64 {
    let largest = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let mut scale = MIN_SLACK_SCALE;
    while scale < largest {
        scale *= 2.0;
    }
    scale
}

/// How many 16-bit height quanta a tile gives each height step: the largest power of two
/// up to 2^14 that keeps `top` steps (its highest vertex above its minimum, `k_min`
/// steps above 0) within 32767 quanta, and its maximum height exact in float32
/// (`k_min * quanta + 32767` below 2^24 in magnitude). The header's maximum, the top of
/// the 16-bit range, is then within twice the tile's own height range (plus a step) instead
/// of 32767 steps up; CesiumJS builds each tile's bounding box from it. Heights stay
/// multiples of the step, exactly, as neighbours decode them.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_is_a_power_of_two_within_a_sixteenth_of_the_bound_and_a_metre() {
        for level in 0..=24 {
            for quality in [0.05, 0.3, 1.0, 4.0] {
                let b = LevelBudget::new(Scheme::MERCATOR, level, quality);
                assert_eq!(b.step.log2().fract(), 0.0);
                assert!(b.step == MIN_HEIGHT_STEP || b.step <= b.bound / STEP_SHARE);
                assert!(b.step * 2.0 > b.bound / STEP_SHARE || b.step == MAX_HEIGHT_STEP);
                assert!(b.decimation(0.0) < b.bound && b.verify(0.0) >= b.bound);
            }
        }
    }

    #[test]
    fn slack_scales_are_powers_of_two_from_16384() {
        assert_eq!(slack_scale([1.0, -300.0, f64::NAN]), 16_384.0);
        assert_eq!(slack_scale([-20_000.0]), 32_768.0);
        assert_eq!(slack_scale([]), 16_384.0);
    }
}
