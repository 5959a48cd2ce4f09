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

/// Fails (before any long work) when the raster's geotransform is singular and world
/// coordinates are to be written: every sample would land on one point or line, and the
/// mesh could not be read back. `--pixel-coords` needs no geotransform.
pub fn check_transform(info: &tinsmith_raster::RasterInfo, pixel_coords: bool) -> Result<()> {
    match info.transform() {
        Some(t) if !pixel_coords && t.is_singular() => bail!(
            "{}: its geotransform {:?} is singular (a pixel size of 0: samples have no \
             distinct positions); assign a real one (e.g. `gdal_translate -of VRT -a_ullr \
             ULX ULY LRX LRY IN OUT.vrt`) or write --pixel-coords",
            info.path.display(),
            t.0
        ),
        _ => Ok(()),
    }
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

    /// The sample whose file coordinates are `p`; fails when `p` is not (within a
    /// thousandth of a pixel) on a sample centre.
    pub fn sample_at(self, p: [f64; 2]) -> Result<[i64; 2]> {
        let s = match self {
            Georef::Pixel => p,
            Georef::World(t) => match t.world_to_sample(p) {
                Some(s) => s,
                None => bail!("the raster's geotransform is singular"),
            },
        };
        let r = [s[0].round(), s[1].round()];
        if !((s[0] - r[0]).abs() <= 1e-3 && (s[1] - r[1]).abs() <= 1e-3) {
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

    /// Whether triangles counter-clockwise in grid coordinates are clockwise in file
    /// coordinates (a north-up raster's rows run south).
    pub fn flips_orientation(self) -> bool {
        matches!(self, Georef::World(t) if t.flips_orientation())
    }
}
