//! Between grid positions and the coordinates written in mesh files: pixel coordinates or
//! the world position of each sample's centre.

use std::fmt;

use crate::{readable, GeoTransform};

/// How far (in pixels) a position in a double-precision file may be from a sample centre
/// and still name it ([`Placement::sample_at`]): far above the rounding of `f64` positions
/// and of the geotransform's inverse (about 1e-10 pixel on the rasters measured), far
/// below a shift of the mesh that could move its error at a sample.
pub const F64_SAMPLE_TOLERANCE: f64 = 1e-7;

/// Up to this far (in pixels) from a sample centre, a position beyond its format's
/// tolerance is named as a sample's, rounded or moved, rather than as a position from
/// another raster or coordinate system.
const NEAR_MISS_PX: f64 = 0.01;

/// The same for the float32 formats (STL, glTF), whose positions are rounded to `f32`
/// around the raster's centre: `mesh` refuses a raster too wide for its positions to land
/// this close to their samples.
pub const F32_SAMPLE_TOLERANCE: f64 = 1e-3;

/// The same for a GeoJSON mesh in WGS84 transformed back into a projected raster's CRS:
/// the two transforms' rounding (about 1e-9 degree) is a fraction of a millimetre.
pub const WGS84_SAMPLE_TOLERANCE: f64 = 1e-5;

/// How grid positions map to the coordinates written in mesh files: pixel (column, row),
/// or a geotransform to the world position of the sample's centre.
///
/// Every method maps an integer position with the same arithmetic, so a sample's file
/// coordinates are the same bits whichever method computed them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// `(column, row)`, as written.
    Pixel,
    /// World coordinates of sample centres through the geotransform.
    World(GeoTransform),
}

/// A file position that names no sample ([`Placement::sample_at`]); the message says
/// how far off it is and what that suggests.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum PositionError {
    /// The geotransform is singular: no position maps back to one sample.
    Singular,
    /// The position is off its nearest sample centre by more than the tolerance, but by no
    /// more than a hundredth of a pixel: a sample's position rounded or moved.
    NearMiss {
        /// The file position.
        position: [f64; 2],
        /// How far off the sample centre it is, in pixels (the larger of the two axes).
        off: f64,
        /// The tolerance it exceeds, in pixels.
        tolerance: f64,
        /// The nearest sample (column, row).
        sample: [f64; 2],
    },
    /// The position is on no sample centre at all (another raster, another CRS, or pixel
    /// coordinates read as world coordinates or the other way round).
    NotOnSample {
        /// The file position.
        position: [f64; 2],
        /// Its fractional grid position (column, row).
        grid: [f64; 2],
        /// Whether the placement was [`Placement::Pixel`].
        pixel: bool,
    },
}

impl fmt::Display for PositionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            PositionError::Singular => write!(f, "the raster's geotransform is singular"),
            PositionError::NearMiss {
                position: p,
                off,
                tolerance,
                sample: r,
            } => write!(
                f,
                "({}, {}) is {off:.1e} pixel off the sample centre ({}, {}), more than the \
                 {tolerance:.0e} pixel its format's rounding allows (rounded or moved off it)",
                readable(p[0]),
                readable(p[1]),
                r[0],
                r[1]
            ),
            PositionError::NotOnSample {
                position: p,
                grid: s,
                pixel,
            } => {
                let grid = |v: f64| {
                    if v.abs() < 1e9 {
                        format!("{v:.4}")
                    } else {
                        format!("{v:.4e}")
                    }
                };
                write!(
                    f,
                    "({}, {}) is not on a sample centre (grid position {}, {}): was the mesh \
                     written from this raster, {}?",
                    readable(p[0]),
                    readable(p[1]),
                    grid(s[0]),
                    grid(s[1]),
                    match pixel {
                        true => "in (column, row) coordinates as --pixel-coords reads it",
                        false => "in its CRS (not with --pixel-coords)",
                    }
                )
            }
        }
    }
}

impl std::error::Error for PositionError {}

/// Why a geotransform cannot give every sample of a grid its own position
/// ([`Placement::check_places_samples`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlacementProblem {
    /// A coefficient is NaN or infinite.
    NotFinite,
    /// The map is singular (a pixel size of 0): samples have no distinct positions.
    Singular,
    /// In `f64` the position of sample `(x, y)` (a corner of the grid) does not map back
    /// to it: pixels too small for the origin.
    PixelsTooSmall {
        /// Column of the sample.
        x: f64,
        /// Row of the sample.
        y: f64,
    },
}

impl Placement {
    /// World coordinates when there is a geotransform and pixel coordinates are not asked
    /// for; pixel coordinates otherwise.
    pub fn new(transform: Option<GeoTransform>, pixel_coords: bool) -> Placement {
        match transform {
            Some(t) if !pixel_coords => Placement::World(t),
            _ => Placement::Pixel,
        }
    }

    /// Vertices `(column, row, height)` in file coordinates ([`Placement::file_position`]),
    /// and triangles reordered ([`Placement::orient`]) to stay counter-clockwise in them
    /// (normals up) where the geotransform flips orientation.
    pub fn file_mesh(
        self,
        vertices: impl IntoIterator<Item = (u32, u32, f64)>,
        triangles: impl IntoIterator<Item = [u32; 3]>,
    ) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let vertices = vertices
            .into_iter()
            .map(|(x, y, z)| {
                let [fx, fy] = self.file_position(x, y);
                [fx, fy, z]
            })
            .collect();
        let triangles = triangles.into_iter().map(|t| self.orient(t)).collect();
        (vertices, triangles)
    }

    /// The least and largest file coordinates of the samples of a `width` x `height` grid
    /// (its corner samples' positions: the map is affine), as `(min, max)`.
    pub fn extent(self, width: u32, height: u32) -> ([f64; 2], [f64; 2]) {
        let (w, h) = (width.saturating_sub(1), height.saturating_sub(1));
        let mut min = [f64::INFINITY; 2];
        let mut max = [f64::NEG_INFINITY; 2];
        for (x, y) in [(0, 0), (w, 0), (0, h), (w, h)] {
            let p = self.file_position(x, y);
            for axis in 0..2 {
                min[axis] = min[axis].min(p[axis]);
                max[axis] = max[axis].max(p[axis]);
            }
        }
        (min, max)
    }

    /// Checks that a `width` x `height` grid written through this placement gives every
    /// sample its own position that maps back to it in `f64` (within
    /// [`F64_SAMPLE_TOLERANCE`]): finite coefficients, a regular map, and pixels not so
    /// small against the origin that positions merge (checked at the corners, where
    /// positions are largest). Pixel coordinates always pass.
    pub fn check_places_samples(self, width: u32, height: u32) -> Result<(), PlacementProblem> {
        let Placement::World(t) = self else {
            return Ok(());
        };
        if t.0.iter().any(|c| !c.is_finite()) {
            return Err(PlacementProblem::NotFinite);
        }
        if t.is_singular() {
            return Err(PlacementProblem::Singular);
        }
        let (w, h) = (f64::from(width.max(1) - 1), f64::from(height.max(1) - 1));
        for (x, y) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)] {
            let back = self.sample_at(t.sample_centre(x, y), F64_SAMPLE_TOLERANCE);
            if back.ok() != Some([x as i64, y as i64]) {
                return Err(PlacementProblem::PixelsTooSmall { x, y });
            }
        }
        Ok(())
    }

    /// File coordinates of sample `(x, y)`.
    pub fn file_position(self, x: u32, y: u32) -> [f64; 2] {
        match self {
            Placement::Pixel => [x as f64, y as f64],
            Placement::World(t) => t.sample_centre(x as f64, y as f64),
        }
    }

    /// File coordinates of the grid position `p` (fractional column, row), by the same
    /// map as [`Placement::file_position`]: an integer position gives the same bits.
    pub fn file_point(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Placement::Pixel => p,
            Placement::World(t) => t.sample_centre(p[0], p[1]),
        }
    }

    /// Whether triangles counter-clockwise in grid coordinates are clockwise in file
    /// coordinates (a north-up raster's rows run south), so that they must be written
    /// reversed to face up.
    pub fn flips_orientation(self) -> bool {
        matches!(self, Placement::World(t) if t.flips_orientation())
    }

    /// Triangle `[a, b, c]` in the orientation to write: counter-clockwise in file
    /// coordinates when it is counter-clockwise in grid coordinates (`[a, c, b]` where
    /// [`Placement::flips_orientation`]).
    pub fn orient(self, [a, b, c]: [u32; 3]) -> [u32; 3] {
        if self.flips_orientation() {
            [a, c, b]
        } else {
            [a, b, c]
        }
    }

    /// The sample whose file coordinates are `p`; fails when `p` is not within `tolerance`
    /// pixels of a sample centre (one of the `*_SAMPLE_TOLERANCE`s, for the file's format),
    /// or within the rounding of `f64` coordinates as large as `p`'s, when that is more.
    ///
    /// # Errors
    /// [`PositionError::Singular`] when the geotransform is singular,
    /// [`PositionError::NearMiss`] when `p` is off by no more than a hundredth of a pixel
    /// ([`Placement::near_miss`]), [`PositionError::NotOnSample`] otherwise.
    pub fn sample_at(self, p: [f64; 2], tolerance: f64) -> Result<[i64; 2], PositionError> {
        let tolerance = tolerance.max(self.f64_rounding(p));
        let Some((s, r, off)) = self.nearest_sample(p) else {
            return Err(PositionError::Singular);
        };
        if off > tolerance && off <= NEAR_MISS_PX {
            return Err(PositionError::NearMiss {
                position: p,
                off,
                tolerance,
                sample: r,
            });
        }
        if off > tolerance {
            return Err(PositionError::NotOnSample {
                position: p,
                grid: s,
                pixel: self == Placement::Pixel,
            });
        }
        Ok([r[0] as i64, r[1] as i64])
    }

    /// The grid position (column, row, fractional) of the file position `p`, the nearest
    /// sample centre and how far off it `p` is in pixels (the larger of the two axes);
    /// `None` when the geotransform is singular.
    fn nearest_sample(self, p: [f64; 2]) -> Option<([f64; 2], [f64; 2], f64)> {
        let s = match self {
            Placement::Pixel => p,
            Placement::World(t) => t.world_to_sample(p)?,
        };
        let r = [s[0].round(), s[1].round()];
        Some((s, r, (s[0] - r[0]).abs().max((s[1] - r[1]).abs())))
    }

    /// Whether the file position `p` is off its nearest sample centre by more than
    /// `tolerance` (and the `f64` rounding [`Placement::sample_at`] allows) but no more
    /// than a hundredth of a pixel: a sample's position rounded or moved, which
    /// [`Placement::sample_at`] names as such.
    pub fn near_miss(self, p: [f64; 2], tolerance: f64) -> bool {
        matches!(
            self.sample_at(p, tolerance),
            Err(PositionError::NearMiss { .. })
        )
    }

    /// A bound, in pixels, on how far `f64` rounding can put the file position `p` of a
    /// sample from it through the inverse geotransform: 64 units of rounding of `p`'s
    /// coordinates, scaled by the inverse's largest row sum, at most 1e-3 pixel (where
    /// rounding is coarser, positions cannot keep samples apart, and the command line
    /// refuses the raster before writing world coordinates). It matters only where pixels
    /// are tiny against the coordinates (millimetre pixels in UTM: about 1e-4 pixel).
    fn f64_rounding(self, p: [f64; 2]) -> f64 {
        let Placement::World(GeoTransform([x0, a, b, y0, c, d])) = self else {
            return 0.0;
        };
        let det = (a * d - b * c).abs();
        let scale = (d.abs() + b.abs()).max(c.abs() + a.abs()) / det;
        let size = p[0].abs() + p[1].abs() + x0.abs() + y0.abs();
        let rounding = 64.0 * f64::EPSILON * size * scale;
        if rounding.is_finite() {
            rounding.min(F32_SAMPLE_TOLERANCE)
        } else {
            0.0
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
        assert_eq!(p.file_position(0, 0), [515.0, 3985.0]);
        assert!(p.flips_orientation());
        assert_eq!(p.orient([1, 2, 3]), [1, 3, 2]);
        let p = Placement::new(Some(north_up), true);
        assert_eq!(p, Placement::Pixel);
        assert_eq!(p.file_position(3, 4), [3.0, 4.0]);
        assert_eq!(p.orient([1, 2, 3]), [1, 2, 3]);
        assert_eq!(Placement::new(None, false), Placement::Pixel);
    }

    #[test]
    fn positions_map_to_samples_within_their_rounding_only() {
        // Millimetre pixels at a UTM northing: f64 positions are off by up to ~1e-4 pixel,
        // which is rounding, so they still name their samples.
        let mm = GeoTransform([500_000.0, 0.001, 0.0, 5_000_000.0, 0.0, -0.001]);
        let placement = Placement::World(mm);
        for (x, y) in [(0.0, 0.0), (429.0, 515.0), (17.0, 300.0)] {
            let p = mm.sample_centre(x, y);
            assert_eq!(
                placement.sample_at(p, F64_SAMPLE_TOLERANCE).unwrap(),
                [x as i64, y as i64]
            );
        }
        // Metre pixels: a shift of 1e-4 pixel is no rounding and is refused, 1e-9 is.
        let m = GeoTransform([500_000.0, 1.0, 0.0, 5_000_000.0, 0.0, -1.0]);
        let placement = Placement::World(m);
        let p = m.sample_centre(10.0, 20.0);
        assert!(placement
            .sample_at([p[0] + 1e-4, p[1]], F64_SAMPLE_TOLERANCE)
            .is_err());
        assert!(placement
            .sample_at([p[0] + 1e-9, p[1]], F64_SAMPLE_TOLERANCE)
            .is_ok());
        assert!(placement
            .sample_at([p[0] + 1e-4, p[1]], F32_SAMPLE_TOLERANCE)
            .is_ok());
    }

    #[test]
    fn messages_name_the_position_and_what_it_suggests() {
        let m = GeoTransform([100.0, 1.0, 0.0, 200.0, 0.0, -1.0]);
        let p = m.sample_centre(10.0, 20.0);
        let err = Placement::World(m)
            .sample_at([p[0] + 1e-3, p[1]], F64_SAMPLE_TOLERANCE)
            .unwrap_err();
        assert!(Placement::World(m).near_miss([p[0] + 1e-3, p[1]], F64_SAMPLE_TOLERANCE));
        assert_eq!(
            err.to_string(),
            "(110.501, 179.5) is 1.0e-3 pixel off the sample centre (10, 20), more \
             than the 1e-7 pixel its format's rounding allows (rounded or moved off it)"
        );
        let err = Placement::Pixel
            .sample_at([2.5, 1e20], F64_SAMPLE_TOLERANCE)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "(2.5, 1e20) is not on a sample centre (grid position 2.5000, 1.0000e20): was the \
             mesh written from this raster, in (column, row) coordinates as --pixel-coords \
             reads it?"
        );
        let singular = GeoTransform([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(
            Placement::World(singular)
                .sample_at([0.0, 0.0], F64_SAMPLE_TOLERANCE)
                .unwrap_err()
                .to_string(),
            "the raster's geotransform is singular"
        );
    }

    #[test]
    fn a_transform_places_samples_apart_or_says_why() {
        let world = |c| Placement::World(GeoTransform(c));
        assert_eq!(
            world([5e5, 30.0, 0.0, 4e6, 0.0, -30.0]).check_places_samples(100, 50),
            Ok(())
        );
        assert_eq!(Placement::Pixel.check_places_samples(100, 50), Ok(()));
        assert_eq!(
            world([0.0, f64::NAN, 0.0, 0.0, 0.0, -1.0]).check_places_samples(3, 3),
            Err(PlacementProblem::NotFinite)
        );
        assert_eq!(
            world([0.0, 1.0, 2.0, 0.0, 0.5, 1.0]).check_places_samples(3, 3),
            Err(PlacementProblem::Singular)
        );
        // Pixels of 1e-12 at an origin of 1e6: positions merge in f64.
        assert!(matches!(
            world([1e6, 1e-12, 0.0, 1e6, 0.0, -1e-12]).check_places_samples(3, 3),
            Err(PlacementProblem::PixelsTooSmall { .. })
        ));
        let (min, max) = world([10.0, 2.0, 0.0, 20.0, 0.0, -2.0]).extent(4, 3);
        assert_eq!((min, max), ([11.0, 15.0], [17.0, 19.0]));
    }
}
