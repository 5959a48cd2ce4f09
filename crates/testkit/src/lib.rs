//! Test support for tinsmith: seeded grid generators and proptest strategies.
//!
//! Grids are plain `(width, height, values)` row-major with NaN for nodata, so this crate
//! depends on no other tinsmith crate and any crate may use it in its tests.

use proptest::prelude::*;

/// A grid as plain data: row-major values, NaN = nodata.
#[derive(Debug, Clone, PartialEq)]
pub struct GridSpec {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major samples; NaN marks nodata.
    pub values: Vec<f64>,
}

/// A small deterministic generator (SplitMix64), so fixtures are reproducible anywhere.
#[derive(Debug, Clone)]
pub struct SplitMix(u64);

impl SplitMix {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> SplitMix {
        SplitMix(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A terrain-like grid: a sum of sine waves plus midpoint-style roughness, seeded.
pub fn terrain(width: u32, height: u32, roughness: f64, seed: u64) -> GridSpec {
    let mut rng = SplitMix::new(seed);
    let waves: Vec<[f64; 4]> = (0..6)
        .map(|_| {
            [
                rng.unit() * 0.2,
                rng.unit() * 0.2,
                rng.unit() * 6.3,
                20.0 + rng.unit() * 80.0,
            ]
        })
        .collect();
    let mut values = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let mut z = 500.0;
            for w in &waves {
                z += w[3] * (w[0] * x as f64 + w[1] * y as f64 + w[2]).sin();
            }
            z += roughness * (rng.unit() - 0.5);
            values.push(z);
        }
    }
    GridSpec {
        width,
        height,
        values,
    }
}

/// Punches nodata into `grid`: a disc of radius `r` at `(cx, cy)`.
pub fn with_nodata_disc(mut grid: GridSpec, cx: f64, cy: f64, r: f64) -> GridSpec {
    for y in 0..grid.height {
        for x in 0..grid.width {
            if (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2) <= r * r {
                grid.values[(y * grid.width + x) as usize] = f64::NAN;
            }
        }
    }
    grid
}

/// Random small grids of every awkward kind: 1xN, 2x2, constant, planar, spiky, quantized
/// and smooth, with or without random nodata holes.
pub fn small_grid() -> impl Strategy<Value = GridSpec> {
    let dims = prop_oneof![
        (1u32..=1, 1u32..12),
        (1u32..12, 1u32..=1),
        (2u32..=2, 2u32..=2),
        (2u32..14, 2u32..14),
        (14u32..48, 14u32..48),
    ];
    (dims, 0u8..6, any::<u64>(), 0u8..4).prop_map(|((w, h), kind, seed, holes)| {
        let mut rng = SplitMix::new(seed);
        let n = (w * h) as usize;
        let mut values: Vec<f64> = match kind {
            0 => vec![rng.unit() * 10.0; n],
            1 => {
                let (a, b) = (rng.unit() * 4.0 - 2.0, rng.unit() * 4.0 - 2.0);
                (0..n)
                    .map(|i| a * (i % w as usize) as f64 + b * (i / w as usize) as f64)
                    .collect()
            }
            2 => (0..n)
                .map(|_| {
                    if rng.unit() < 0.15 {
                        100.0 * rng.unit()
                    } else {
                        rng.unit()
                    }
                })
                .collect(),
            3 => (0..n).map(|_| (rng.unit() * 8.0).floor()).collect(),
            4 => terrain(w, h, 3.0, seed).values,
            _ => (0..n).map(|_| rng.unit() * 1000.0 - 500.0).collect(),
        };
        for _ in 0..holes {
            let (cx, cy) = (rng.unit() * w as f64, rng.unit() * h as f64);
            let r = rng.unit() * 2.5;
            for y in 0..h {
                for x in 0..w {
                    if (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2) <= r * r {
                        values[(y * w + x) as usize] = f64::NAN;
                    }
                }
            }
        }
        GridSpec {
            width: w,
            height: h,
            values,
        }
    })
}

/// Error bounds worth testing: zero, tiny, typical and huge.
pub fn max_error() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), 1e-9..1e-3, 0.01..5.0, 5.0..1000.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generators_are_reproducible() {
        assert_eq!(terrain(9, 7, 2.0, 42), terrain(9, 7, 2.0, 42));
        assert_ne!(terrain(9, 7, 2.0, 42), terrain(9, 7, 2.0, 43));
    }

    #[test]
    fn disc_makes_nodata() {
        let g = with_nodata_disc(terrain(10, 10, 0.0, 1), 5.0, 5.0, 2.0);
        assert_eq!(g.values.iter().filter(|v| v.is_nan()).count(), 13);
    }
}
