//! Shaded relief, as `gdaldem hillshade` computes it by default.

/// The shade (1 to 255) of every sample of a `width x height` grid (row-major, row 0
/// first as the raster stores it, NaN for nodata), by `gdaldem hillshade`'s default
/// algorithm: Horn's slopes over the 3 x 3 window, light from azimuth 315° at altitude
/// 45°, z factor 1. `resolution` is the `[east-west, north-south]` sample spacing in the
/// heights' unit, the second negative for a north-up raster (GDAL's `geotransform[1]` and
/// `[5]`). Where a neighbour is nodata or outside the grid, the sample's own height stands
/// in for it (GDAL leaves such samples out unless `-compute_edges`); nodata samples get
/// NaN.
pub fn hillshade(values: &[f64], width: usize, height: usize, resolution: [f64; 2]) -> Vec<f32> {
    let (azimuth, altitude) = (315f64.to_radians(), 45f64.to_radians());
    let (sin_alt, cos_alt) = altitude.sin_cos();
    let (sin_az, cos_az) = azimuth.sin_cos();
    let inv_ew = 1.0 / (8.0 * resolution[0]);
    let inv_ns = 1.0 / (8.0 * resolution[1]);
    let mut out = vec![f32::NAN; width * height];
    for j in 0..height {
        for i in 0..width {
            let centre = values[j * width + i];
            if !centre.is_finite() {
                continue;
            }
            let at = |di: isize, dj: isize| -> f64 {
                let (x, y) = (i as isize + di, j as isize + dj);
                if x < 0 || y < 0 || x >= width as isize || y >= height as isize {
                    return centre;
                }
                let v = values[y as usize * width + x as usize];
                if v.is_finite() {
                    v
                } else {
                    centre
                }
            };
            let w = [
                at(-1, -1),
                at(0, -1),
                at(1, -1),
                at(-1, 0),
                centre,
                at(1, 0),
                at(-1, 1),
                at(0, 1),
                at(1, 1),
            ];
            let x = ((w[0] + 2.0 * w[3] + w[6]) - (w[2] + 2.0 * w[5] + w[8])) * inv_ew;
            let y = ((w[6] + 2.0 * w[7] + w[8]) - (w[0] + 2.0 * w[1] + w[2])) * inv_ns;
            let cang = (sin_alt - (y * cos_az * cos_alt - x * sin_az * cos_alt))
                / (1.0 + x * x + y * y).sqrt();
            out[j * width + i] = if cang <= 0.0 {
                1.0
            } else {
                (1.0 + 254.0 * cang) as f32
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_ground_is_lit_by_the_altitude_and_slopes_facing_the_light_are_brighter() {
        let flat = hillshade(&[5.0; 9], 3, 3, [1.0, -1.0]);
        let expected = 1.0 + 254.0 * 45f64.to_radians().sin();
        assert!((f64::from(flat[4]) - expected).abs() < 1e-3);
        // Rising to the south-east (row 0 is north), so facing the north-west light:
        // brighter; the other way round, darker.
        let ramp: Vec<f64> = (0..9).map(|k| ((k % 3) + (k / 3)) as f64).collect();
        let facing = hillshade(&ramp, 3, 3, [1.0, -1.0]);
        let away: Vec<f64> = ramp.iter().map(|v| -v).collect();
        let away = hillshade(&away, 3, 3, [1.0, -1.0]);
        assert!(away[4] < flat[4] && flat[4] < facing[4]);
        let mut hole = [1.0; 9];
        hole[4] = f64::NAN;
        assert!(hillshade(&hole, 3, 3, [1.0, -1.0])[4].is_nan());
    }
}
