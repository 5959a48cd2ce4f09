//! Where raster positions go in the written files: pixel coordinates or the world
//! position of each sample's centre.

use tinsmith_core::GeoTransform;

/// How raster positions map to the coordinates written in mesh files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// `(column, row)`, as written.
    Pixel,
    /// World coordinates of sample centres through the geotransform.
    World(GeoTransform),
}

impl Placement {
    /// World coordinates when there is a geotransform and pixel coordinates are not asked
    /// for; pixel coordinates otherwise (as `tinsmith mesh` writes untiled meshes).
    pub fn new(transform: Option<GeoTransform>, pixel_coords: bool) -> Placement {
        match transform {
            Some(t) if !pixel_coords => Placement::World(t),
            _ => Placement::Pixel,
        }
    }

    /// File coordinates of raster sample `(x, y)`.
    pub fn position(self, x: u32, y: u32) -> [f64; 2] {
        match self {
            Placement::Pixel => [x as f64, y as f64],
            Placement::World(t) => t.sample_centre(x as f64, y as f64),
        }
    }

    /// Whether triangles counter-clockwise in raster coordinates are clockwise in file
    /// coordinates (a north-up raster's rows run south), so that they must be written
    /// reversed to face up.
    pub fn flips_orientation(self) -> bool {
        matches!(self, Placement::World(t) if t.flips_orientation())
    }

    /// Triangle `t` in the orientation to write (counter-clockwise in file coordinates).
    pub(crate) fn orient(self, [a, b, c]: [u32; 3]) -> [u32; 3] {
        if self.flips_orientation() {
            [a, c, b]
        } else {
            [a, b, c]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn north_up_rasters_flip_and_pixels_do_not() {
        let north_up = GeoTransform([500.0, 30.0, 0.0, 4000.0, 0.0, -30.0]);
        let p = Placement::new(Some(north_up), false);
        assert_eq!(p.position(0, 0), [515.0, 3985.0]);
        assert!(p.flips_orientation());
        assert_eq!(p.orient([1, 2, 3]), [1, 3, 2]);
        let p = Placement::new(Some(north_up), true);
        assert_eq!(p, Placement::Pixel);
        assert_eq!(p.position(3, 4), [3.0, 4.0]);
        assert_eq!(p.orient([1, 2, 3]), [1, 2, 3]);
        assert_eq!(Placement::new(None, false), Placement::Pixel);
    }
}
