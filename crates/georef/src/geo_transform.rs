//! The affine map from grid positions to world coordinates (GDAL's geotransform).

/// GDAL's six-coefficient affine geotransform, mapping a pixel *corner* position
/// `(col, row)` to world `(x, y)`:
/// `x = c[0] + col * c[1] + row * c[2]`, `y = c[3] + col * c[4] + row * c[5]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoTransform(pub [f64; 6]);

impl GeoTransform {
    /// The identity: world coordinates equal pixel-corner coordinates.
    pub const IDENTITY: GeoTransform = GeoTransform([0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);

    /// World position of the centre of sample `(x, y)` (column, row), i.e. of pixel corner
    /// position `(x + 0.5, y + 0.5)`.
    pub fn sample_centre(&self, x: f64, y: f64) -> [f64; 2] {
        let c = &self.0;
        let (col, row) = (x + 0.5, y + 0.5);
        [
            c[0] + col * c[1] + row * c[2],
            c[3] + col * c[4] + row * c[5],
        ]
    }

    /// Whether the transform maps the grid onto a line or a point (a pixel size of 0,
    /// parallel axes) or has a non-finite coefficient: samples then have no distinct
    /// positions, and no position maps back to one sample.
    pub fn is_singular(&self) -> bool {
        let c = &self.0;
        let det = c[1] * c[5] - c[2] * c[4];
        det == 0.0 || !det.is_finite() || c.iter().any(|v| !v.is_finite())
    }

    /// The sample `(x, y)` whose centre maps to `world`, as fractional grid coordinates,
    /// or `None` when the transform is singular.
    pub fn world_to_sample(&self, world: [f64; 2]) -> Option<[f64; 2]> {
        let c = &self.0;
        let det = c[1] * c[5] - c[2] * c[4];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (dx, dy) = (world[0] - c[0], world[1] - c[3]);
        let col = (c[5] * dx - c[2] * dy) / det;
        let row = (-c[4] * dx + c[1] * dy) / det;
        Some([col - 0.5, row - 0.5])
    }

    /// Whether the map flips orientation (true for the usual north-up raster, whose rows go
    /// south): a triangle counter-clockwise in grid coordinates is then clockwise in world
    /// coordinates.
    pub fn flips_orientation(&self) -> bool {
        self.0[1] * self.0[5] - self.0[2] * self.0[4] < 0.0
    }
}
