//! Bilinear interpolation between pixel centres: which four pixels a point reads, with
//! which weights, and their weighted mean over the valid ones.

/// Which pixels a raster has: rows `0..height`, and columns `0..width`, or every column
/// taken modulo `turn` for a raster whose first `turn` columns go all the way round the
/// globe (its columns then wrap, and the pixels either side of the seam are neighbours).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PixelGrid {
    /// Columns.
    pub(crate) width: i64,
    /// Rows.
    pub(crate) height: i64,
    /// Columns in one turn of longitude, for a raster that wraps.
    pub(crate) turn: Option<i64>,
}

impl PixelGrid {
    /// Whether the point at pixel coordinates `col`, `row` (from the raster's top-left
    /// corner, in pixels) lies within the raster's pixel edges, borders included. Where the
    /// columns wrap, any column does.
    pub(crate) fn contains(&self, col: f64, row: f64) -> bool {
        let inside = |v: f64, len: i64| (0.0..=len as f64).contains(&v);
        inside(row, self.height)
            && ((self.turn.is_some() && col.is_finite()) || inside(col, self.width))
    }
}

/// The four pixel centres around a point and their weights: pixels `x0`, `x0 + 1` by
/// `y0`, `y0 + 1` (columns before any wrapping), weighted `1 - tx`, `tx` across and
/// `1 - ty`, `ty` down.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Footprint {
    /// Column of the left pixels.
    pub(crate) x0: i64,
    /// Row of the upper pixels.
    pub(crate) y0: i64,
    /// Fraction of the way from the left pixels' centres to the right ones'.
    tx: f64,
    /// Fraction of the way from the upper pixels' centres to the lower ones'.
    ty: f64,
}

impl Footprint {
    /// The footprint of the point at pixel coordinates `col`, `row` (finite; pixel
    /// `(x, y)`'s centre is at `x + 0.5`, `y + 0.5`).
    pub(crate) fn at(col: f64, row: f64) -> Footprint {
        let (fx, fy) = (col - 0.5, row - 0.5);
        let (x0, y0) = (floor(fx), floor(fy));
        Footprint {
            x0: x0 as i64,
            y0: y0 as i64,
            tx: fx - x0,
            ty: fy - y0,
        }
    }

    /// The weighted mean of the valid pixels among the four whose weight is not zero, as
    /// `pixel(x, y)` gives them (NaN for nodata or outside the raster): each weight
    /// divided by the sum of the weights used. NaN when none is valid. The terms are
    /// summed in one fixed order, so the result depends on the four pixels and the
    /// weights only.
    pub(crate) fn interpolate(&self, pixel: impl Fn(i64, i64) -> f64) -> f64 {
        let mut values = [f64::NAN; 4];
        for (k, (w, v)) in self.weights().into_iter().zip(&mut values).enumerate() {
            if w != 0.0 {
                *v = pixel(self.x0 + (k & 1) as i64, self.y0 + (k >> 1) as i64);
            }
        }
        self.mean(values)
    }

    /// The weights of pixels (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1).
    fn weights(&self) -> [f64; 4] {
        let (wx, wy) = ([1.0 - self.tx, self.tx], [1.0 - self.ty, self.ty]);
        [wx[0] * wy[0], wx[1] * wy[0], wx[0] * wy[1], wx[1] * wy[1]]
    }

    /// The weighted mean of `values` (in [`Footprint::weights`]' order) over those of
    /// nonzero weight that are valid, summed in that order; NaN when there are none.
    fn mean(&self, values: [f64; 4]) -> f64 {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (w, v) in self.weights().into_iter().zip(values) {
            if w != 0.0 && v.is_finite() {
                sum += w * v;
                weight += w;
            }
        }
        if weight > 0.0 {
            sum / weight
        } else {
            f64::NAN
        }
    }
}

impl Footprint {
    /// [`Footprint::interpolate`] of the pixels of `grid` in `window` (which holds every
    /// pixel of nonzero weight inside the raster): the same value, the four pixels read
    /// directly from the window when they all lie in it and in the raster.
    pub(crate) fn interpolate_in(&self, window: &Window, grid: &PixelGrid) -> f64 {
        let in_raster = self.y0 >= 0
            && self.y0 + 1 < grid.height
            && (grid.turn.is_some() || (self.x0 >= 0 && self.x0 + 1 < grid.width));
        let (i, j) = (self.x0 - window.x0, self.y0 - window.y0);
        if in_raster
            && i >= 0
            && j >= 0
            && i + 1 < window.width as i64
            && j + 1 < window.height as i64
        {
            let at = j as usize * window.width + i as usize;
            let (below, above) = window.values[at..].split_at(window.width);
            return self.mean([below[0], below[1], above[0], above[1]]);
        }
        self.interpolate(|x, y| window.pixel(grid, x, y))
    }
}

/// `v.floor()` for a finite `v`, without the library call the target's instruction set
/// needs for it (the same value: truncation is exact, then one step down for negative
/// non-integers; beyond 2^52 every `f64` is an integer).
fn floor(v: f64) -> f64 {
    if v.abs() >= 4_503_599_627_370_496.0 {
        return v;
    }
    let t = v as i64 as f64;
    if t > v {
        t - 1.0
    } else {
        t
    }
}

/// A rectangle of decoded pixels: columns `x0 .. x0 + width` (before any wrapping, so a
/// window can reach across the seam of a raster whose columns wrap), rows `y0 .. y0 +
/// height`, row-major, NaN for nodata.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Window {
    pub(crate) x0: i64,
    pub(crate) y0: i64,
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) values: Vec<f64>,
}

impl Window {
    /// Pixel `x`, `y` of `grid`: NaN outside the raster.
    ///
    /// # Panics
    /// When the pixel is in the raster but not in the window.
    pub(crate) fn pixel(&self, grid: &PixelGrid, x: i64, y: i64) -> f64 {
        // Where the columns wrap, every column is in the raster.
        if y < 0 || y >= grid.height || (grid.turn.is_none() && !(0..grid.width).contains(&x)) {
            return f64::NAN;
        }
        let (i, j) = (x - self.x0, y - self.y0);
        assert!(
            (0..self.width as i64).contains(&i) && (0..self.height as i64).contains(&j),
            "pixel ({x}, {y}) outside the window read"
        );
        self.values[j as usize * self.width + i as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRID: PixelGrid = PixelGrid {
        width: 3,
        height: 2,
        turn: None,
    };

    fn window(values: [f64; 6]) -> Window {
        Window {
            x0: 0,
            y0: 0,
            width: 3,
            height: 2,
            values: values.to_vec(),
        }
    }

    #[test]
    fn floor_is_the_library_floor() {
        let values = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.75,
            -2.75,
            1e-300,
            -1e-300,
            4503599627370495.5,
            -4503599627370495.5,
            9e15,
            -9e15,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
        ];
        for v in values {
            assert_eq!(floor(v), v.floor(), "{v}");
        }
        for k in -2000..2000 {
            let v = f64::from(k) * 0.37;
            assert_eq!(floor(v), v.floor(), "{v}");
        }
    }

    #[test]
    fn a_point_between_four_centres_is_their_bilinear_mean() {
        let w = window([0.0, 10.0, 20.0, 100.0, 110.0, 120.0]);
        let at = |c, r| Footprint::at(c, r).interpolate(|x, y| w.pixel(&GRID, x, y));
        assert_eq!(at(0.5, 0.5), 0.0);
        assert_eq!(at(1.0, 1.0), 55.0);
        assert_eq!(at(1.75, 0.5), 12.5);
        // On a centre, the neighbours' weights are zero: their values do not matter.
        assert_eq!(at(2.5, 1.5), 120.0);
    }

    #[test]
    fn invalid_and_outside_neighbours_get_no_weight() {
        let w = window([0.0, f64::NAN, 20.0, 100.0, 110.0, 120.0]);
        let at = |c, r| Footprint::at(c, r).interpolate(|x, y| w.pixel(&GRID, x, y));
        // (0,0) weight 1/4, (1,0) invalid, (0,1) 1/4, (1,1) 1/4.
        assert!((at(1.0, 1.0) - 70.0).abs() < 1e-12);
        // Near the left border: column -1 is outside, the rest is renormalised.
        assert_eq!(at(0.25, 0.5), 0.0);
        assert_eq!(at(0.0, 2.0), 100.0);
        // Only the invalid neighbour has weight: no value.
        assert!(at(1.5, 0.5).is_nan());
        let none = window([f64::NAN; 6]);
        assert!(Footprint::at(1.2, 1.2)
            .interpolate(|x, y| none.pixel(&GRID, x, y))
            .is_nan());
    }

    #[test]
    fn wrapped_columns_read_across_the_seam() {
        let grid = PixelGrid {
            width: 4,
            height: 1,
            turn: Some(3),
        };
        assert!(grid.contains(7.0, 0.5) && !grid.contains(1.0, 1.5));
        assert!(!GRID.contains(3.01, 1.0) && GRID.contains(3.0, 2.0));
        // Columns -1 and 0 (the raster's 2 and 0), read as one window.
        let w = Window {
            x0: -1,
            y0: 0,
            width: 2,
            height: 1,
            values: vec![30.0, 0.0],
        };
        let v = Footprint::at(0.25, 0.5).interpolate(|x, y| w.pixel(&grid, x, y));
        assert_eq!(v, 7.5);
    }
}
