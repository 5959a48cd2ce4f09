//! Where water is: the quantized-mesh `watermask` extension (id 2), 256 x 256 cells a
//! tile, north to south and west to east, 255 for water and 0 for land; one byte when the
//! whole tile is one or the other. CesiumJS draws water (`requestWaterMask`) from it.

use std::path::PathBuf;

use tinsmith_raster::{sample_geographic, GeoLattice, VerticalDatum};

use crate::quantized_mesh::GeoRectangle;
use crate::TerrainResult;

/// Cells a side of a tile's water mask.
pub const MASK_CELLS: u32 = 256;

/// Where a pyramid's water comes from. Each tile's mask depends only on the source and
/// the tile's rectangle: it is read at its cells' centres.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Water {
    /// A raster of water (1) and land (0): a cell is water where the raster, interpolated
    /// bilinearly at its centre, is at least 0.5; nodata and outside the raster is land.
    Raster {
        /// The mask raster, any CRS GDAL reprojects.
        path: PathBuf,
        /// Its band, 1-based.
        band: usize,
    },
    /// A polygon layer GDAL reads (seas, lakes, a coastline's land polygons inverted): a
    /// cell is water where its centre lies inside a polygon of any of the file's layers.
    Polygons {
        /// The vector file, any CRS PROJ transforms.
        path: PathBuf,
    },
    /// The pyramid's own DEM: a cell is water where the DEM has no data at its centre
    /// (nodata sea), or where its height is at or below 0 and one of the 8 cells around it
    /// has no data (the shore of that sea). Valid samples below 0 away from nodata (a
    /// polder, the Dead Sea, bathymetry) are land.
    SeaLevel {
        /// The DEM.
        path: PathBuf,
        /// Its band, 1-based.
        band: usize,
    },
}

impl Water {
    /// A name for the source that is the same on every machine: the kind and the file's
    /// name (not its directory).
    pub fn label(&self) -> String {
        let name = |p: &PathBuf| {
            p.file_name()
                .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
        };
        match self {
            Water::Raster { path, band } => format!("raster:{}:{band}", name(path)),
            Water::Polygons { path } => format!("polygons:{}", name(path)),
            Water::SeaLevel { band, .. } => format!("sea-level:{band}"),
        }
    }
}

/// A tile's water mask.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Mask {
    /// Every cell is land: one byte, 0.
    Land,
    /// Every cell is water: one byte, 255.
    Water,
    /// `MASK_CELLS`^2 bytes, row 0 the northernmost.
    Cells(Vec<u8>),
}

impl Mask {
    /// The extension's bytes.
    pub(crate) fn bytes(&self) -> &[u8] {
        match self {
            Mask::Land => &[0],
            Mask::Water => &[255],
            Mask::Cells(cells) => cells,
        }
    }
}

/// The water mask of the tile covering `rect`.
pub(crate) fn mask(water: &Water, rect: GeoRectangle) -> TerrainResult<Mask> {
    let n = MASK_CELLS as usize;
    let step = (rect.east - rect.west) / f64::from(MASK_CELLS);
    // Cell centres, one ring beyond the tile for the shore rule: row 0 the southernmost.
    let lattice = |ring: u32| GeoLattice {
        latitudes: tinsmith_raster::Latitudes::Uniform,
        west: rect.west + step / 2.0 - f64::from(ring) * step,
        south: rect.south + step / 2.0 - f64::from(ring) * step,
        step,
        first_column: 0,
        first_row: 0,
        width: MASK_CELLS + 2 * ring,
        height: MASK_CELLS + 2 * ring,
    };
    let mut cells = vec![0u8; n * n];
    match water {
        Water::Raster { path, band } => {
            let values = sample_geographic(
                path,
                *band,
                &lattice(0),
                &VerticalDatum::Ellipsoid,
                f32::NAN,
            )?;
            for (k, v) in values.iter().enumerate() {
                let (i, j) = (k % n, k / n);
                if *v >= 0.5 {
                    cells[(n - 1 - j) * n + i] = 255;
                }
            }
        }
        Water::Polygons { path } => {
            cells = tinsmith_raster::burn_polygons(
                path,
                [rect.west, rect.south, rect.east, rect.north],
                MASK_CELLS,
            )?;
        }
        Water::SeaLevel { path, band } => {
            let wide = n + 2;
            let values = sample_geographic(
                path,
                *band,
                &lattice(1),
                &VerticalDatum::Ellipsoid,
                f32::NAN,
            )?;
            // Cells of the ring beyond a pole are not on the globe: never nodata sea.
            let on_globe = |j: usize| {
                let lat = rect.south + step / 2.0 + (j as f64 - 1.0) * step;
                (-90.0..=90.0).contains(&lat)
            };
            let no_data = |i: usize, j: usize| on_globe(j) && !values[j * wide + i].is_finite();
            for j in 0..n {
                for i in 0..n {
                    let v = values[(j + 1) * wide + i + 1];
                    let shore = || (0..3).any(|dj| (0..3).any(|di| no_data(i + di, j + dj)));
                    if !v.is_finite() || (v <= 0.0 && shore()) {
                        cells[(n - 1 - j) * n + i] = 255;
                    }
                }
            }
        }
    }
    Ok(if cells.iter().all(|&c| c == 0) {
        Mask::Land
    } else if cells.iter().all(|&c| c == 255) {
        Mask::Water
    } else {
        Mask::Cells(cells)
    })
}
