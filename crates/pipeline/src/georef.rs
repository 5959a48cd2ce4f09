//! Between grid positions and the coordinates written in mesh files.

use std::path::Path;

use anyhow::{bail, Result};
use tinsmith_core::GeoTransform;

use crate::number::readable;

/// How grid positions map to file coordinates: pixel (column, row) or a geotransform to
/// the world position of the sample's centre.
#[derive(Debug, Clone, Copy)]
pub enum Georef {
    /// `(column, row)` as written.
    Pixel,
    /// World coordinates of sample centres.
    World(GeoTransform),
}

/// How far (in pixels) a position in a double-precision file may be from a sample centre
/// and still name it ([`Georef::sample_at`]): far above the rounding of `f64` positions
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

/// Fails (before any long work) when world coordinates are to be written and the raster's
/// geotransform cannot give every sample its own: a non-finite coefficient, a singular map
/// (every sample on one point or line), or pixels so small against the origin that `f64`
/// positions no longer map back to their samples (checked at the grid's corners, where
/// positions are largest). The mesh could not be read back. `--pixel-coords` needs no
/// geotransform.
pub fn check_transform(info: &tinsmith_raster::RasterInfo, pixel_coords: bool) -> Result<()> {
    let Some(t) = info.transform().filter(|_| !pixel_coords) else {
        return Ok(());
    };
    let input = info.path.display();
    let fix = "assign a real one (e.g. `gdal_translate -of VRT -a_ullr ULX ULY LRX LRY IN \
               OUT.vrt`) or write --pixel-coords";
    if t.0.iter().any(|c| !c.is_finite()) {
        bail!(
            "{input}: its geotransform {:?} has a coefficient that is not a finite number; {fix}",
            t.0
        );
    }
    if t.is_singular() {
        bail!(
            "{input}: its geotransform {:?} is singular (a pixel size of 0: samples have no \
             distinct positions); {fix}",
            t.0
        );
    }
    let (w, h) = (
        f64::from(info.width.max(1) - 1),
        f64::from(info.height.max(1) - 1),
    );
    for (x, y) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)] {
        // Mapped back as `verify` maps a double-precision file's positions.
        let back = Georef::World(t).sample_at(t.sample_centre(x, y), F64_SAMPLE_TOLERANCE);
        if back.ok() != Some([x as i64, y as i64]) {
            bail!(
                "{input}: its geotransform {:?} has pixels too small for its origin: in f64 \
                 the position of sample ({x}, {y}) does not map back to it, so samples would \
                 share positions; {fix}",
                t.0
            );
        }
    }
    Ok(())
}

/// [`check_transform`] on the band's metadata alone (no sample is read); returns the
/// raster's width and height.
pub fn check_input_transform(input: &Path, band: usize, pixel_coords: bool) -> Result<(u32, u32)> {
    let reader = tinsmith_raster::WindowReader::open(input, band)?;
    check_transform(reader.info(), pixel_coords)?;
    Ok((reader.width(), reader.height()))
}

impl Georef {
    /// Pixel coordinates when asked for or when the raster has no geotransform.
    pub fn new(transform: Option<GeoTransform>, pixel_coords: bool) -> Georef {
        match transform {
            Some(t) if !pixel_coords => Georef::World(t),
            _ => Georef::Pixel,
        }
    }

    /// Vertices `(column, row, height)` in file coordinates, and triangles reordered to
    /// stay counter-clockwise in them (normals up) where the geotransform flips
    /// orientation.
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
        let flip = self.flips_orientation();
        let triangles = triangles
            .into_iter()
            .map(|[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
            .collect();
        (vertices, triangles)
    }

    /// File coordinates of sample `(x, y)`.
    pub fn file_position(self, x: u32, y: u32) -> [f64; 2] {
        match self {
            Georef::Pixel => [x as f64, y as f64],
            Georef::World(t) => t.sample_centre(x as f64, y as f64),
        }
    }

    /// File coordinates of the grid position `p` (fractional column, row), by the same
    /// map as [`Georef::file_position`]: an integer position gives the same bits.
    pub fn file_point(self, p: [f64; 2]) -> [f64; 2] {
        match self {
            Georef::Pixel => p,
            Georef::World(t) => t.sample_centre(p[0], p[1]),
        }
    }

    /// The sample whose file coordinates are `p`; fails when `p` is not within `tolerance`
    /// pixels of a sample centre (one of the `*_SAMPLE_TOLERANCE`s, for the file's format),
    /// or within the rounding of `f64` coordinates as large as `p`'s, when that is more.
    pub fn sample_at(self, p: [f64; 2], tolerance: f64) -> Result<[i64; 2]> {
        let tolerance = tolerance.max(self.f64_rounding(p));
        let Some((s, r, off)) = self.nearest_sample(p) else {
            bail!("the raster's geotransform is singular");
        };
        if off > tolerance && off <= NEAR_MISS_PX {
            bail!(
                "({}, {}) is {off:.1e} pixel off the sample centre ({}, {}), more than the \
                 {tolerance:.0e} pixel its format's rounding allows (rounded or moved off it)",
                readable(p[0]),
                readable(p[1]),
                r[0],
                r[1]
            );
        }
        if off > tolerance {
            let grid = |v: f64| {
                if v.abs() < 1e9 {
                    format!("{v:.4}")
                } else {
                    format!("{v:.4e}")
                }
            };
            bail!(
                "({}, {}) is not on a sample centre (grid position {}, {}): was the mesh \
                 written from this raster, {}?",
                readable(p[0]),
                readable(p[1]),
                grid(s[0]),
                grid(s[1]),
                match self {
                    Georef::Pixel => "in (column, row) coordinates as --pixel-coords reads it",
                    Georef::World(_) => "in its CRS (not with --pixel-coords)",
                }
            );
        }
        Ok([r[0] as i64, r[1] as i64])
    }

    /// The grid position (column, row, fractional) of the file position `p`, the nearest
    /// sample centre and how far off it `p` is in pixels (the larger of the two axes);
    /// `None` when the geotransform is singular.
    fn nearest_sample(self, p: [f64; 2]) -> Option<([f64; 2], [f64; 2], f64)> {
        let s = match self {
            Georef::Pixel => p,
            Georef::World(t) => t.world_to_sample(p)?,
        };
        let r = [s[0].round(), s[1].round()];
        Some((s, r, (s[0] - r[0]).abs().max((s[1] - r[1]).abs())))
    }

    /// Whether the file position `p` is off its nearest sample centre by more than
    /// `tolerance` (and the `f64` rounding [`Georef::sample_at`] allows) but no more than
    /// a hundredth of a pixel: a sample's position rounded or moved, which
    /// [`Georef::sample_at`] names as such.
    pub fn near_miss(self, p: [f64; 2], tolerance: f64) -> bool {
        let tolerance = tolerance.max(self.f64_rounding(p));
        self.nearest_sample(p)
            .is_some_and(|(_, _, off)| off > tolerance && off <= NEAR_MISS_PX)
    }

    /// A bound, in pixels, on how far `f64` rounding can put the file position `p` of a
    /// sample from it through the inverse geotransform: 64 units of rounding of `p`'s
    /// coordinates, scaled by the inverse's largest row sum, at most 1e-3 pixel (where
    /// rounding is coarser, positions cannot keep samples apart, and [`check_transform`]
    /// refuses the raster). It matters only where pixels are tiny against the coordinates
    /// (millimetre pixels in UTM: about 1e-4 pixel).
    fn f64_rounding(self, p: [f64; 2]) -> f64 {
        let Georef::World(GeoTransform([x0, a, b, y0, c, d])) = self else {
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

    /// Whether triangles counter-clockwise in grid coordinates are clockwise in file
    /// coordinates (a north-up raster's rows run south).
    pub fn flips_orientation(self) -> bool {
        matches!(self, Georef::World(t) if t.flips_orientation())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_map_to_samples_within_their_rounding_only() {
        // Millimetre pixels at a UTM northing: f64 positions are off by up to ~1e-4 pixel,
        // which is rounding, so they still name their samples.
        let mm = GeoTransform([500_000.0, 0.001, 0.0, 5_000_000.0, 0.0, -0.001]);
        let georef = Georef::World(mm);
        for (x, y) in [(0.0, 0.0), (429.0, 515.0), (17.0, 300.0)] {
            let p = mm.sample_centre(x, y);
            assert_eq!(
                georef.sample_at(p, F64_SAMPLE_TOLERANCE).unwrap(),
                [x as i64, y as i64]
            );
        }
        // Metre pixels: a shift of 1e-4 pixel is no rounding and is refused, 1e-9 is.
        let m = GeoTransform([500_000.0, 1.0, 0.0, 5_000_000.0, 0.0, -1.0]);
        let georef = Georef::World(m);
        let p = m.sample_centre(10.0, 20.0);
        assert!(georef
            .sample_at([p[0] + 1e-4, p[1]], F64_SAMPLE_TOLERANCE)
            .is_err());
        assert!(georef
            .sample_at([p[0] + 1e-9, p[1]], F64_SAMPLE_TOLERANCE)
            .is_ok());
        assert!(georef
            .sample_at([p[0] + 1e-4, p[1]], F32_SAMPLE_TOLERANCE)
            .is_ok());
    }
}
