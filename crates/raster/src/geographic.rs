//! A raster's place in EPSG:4326: its geographic bounds and resolution, and the regular
//! longitude/latitude lattices it is sampled on (see [`crate::sample_geographic`]).

use std::path::Path;

use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};

use crate::error::{gdal_reason, Error, Result};
use crate::info::RasterInfo;
use crate::read::OpenBand;

/// Where a raster lies in EPSG:4326 (degrees), and how fine it is. `west` is in
/// `[-180, 180]`, or beyond 180 for a raster wholly east of it (the far part of a 0..360
/// grid, kept in its own frame), and `east` after it: beyond 180 when the raster crosses
/// the antimeridian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoBounds {
    /// West longitude.
    pub west: f64,
    /// South latitude.
    pub south: f64,
    /// East longitude, `west < east <= west + 360`; above 180 across the antimeridian.
    pub east: f64,
    /// North latitude.
    pub north: f64,
    /// The finer of the longitude and latitude spans per sample, in degrees, but no finer
    /// than an eighth of their geometric mean: a lattice this fine holds at most 64 times
    /// the raster's samples, however tall or wide its pixels.
    pub resolution: f64,
}

/// A lattice of sample positions in EPSG:4326, a window of a larger one: column `i`, row
/// `j` is the larger lattice's column `first_column + i`, row `first_row + j`, at longitude
/// `west + (first_column + i) * step` and, with [`Latitudes::Uniform`] rows, latitude
/// `south + (first_row + j) * step` (row 0 is the southernmost). A point's position depends
/// only on its index in the larger lattice, never on the window: [`GeoLattice::lon`] and
/// [`GeoLattice::lat`] compute it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoLattice {
    /// Longitude of the larger lattice's column 0.
    pub west: f64,
    /// Latitude of the larger lattice's row 0.
    pub south: f64,
    /// Spacing in degrees.
    pub step: f64,
    /// The larger lattice's column that is this one's column 0.
    pub first_column: u64,
    /// The larger lattice's row that is this one's row 0.
    pub first_row: u64,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// How the larger lattice's rows are spaced in latitude.
    pub latitudes: Latitudes,
}

/// How a [`GeoLattice`]'s rows are spaced in latitude.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Latitudes {
    /// Row `r` of the larger lattice at `south + r * step`.
    #[default]
    Uniform,
    /// Web Mercator tiles (EPSG:3857), `tiles` of them from the south edge (about
    /// -85.05°) to the north edge, each `cells` rows spaced evenly in latitude between its
    /// southern and northern edges (each edge at [`web_mercator_latitude`] of its Web
    /// Mercator y): row `cells t + j` lies `j / cells` of the way up tile `t`. Two tiles
    /// share the row on their common edge (it is the same latitude, to the bit).
    /// `south` is not used.
    WebMercatorTiles {
        /// Rows a tile.
        cells: u32,
        /// Tiles from south to north.
        tiles: u64,
    },
}

/// The latitude (degrees) of Web Mercator `y`, in turns from the south edge of the square
/// world (0: about -85.0511°, 1/2: the equator, 1: about 85.0511°), as CesiumJS's
/// `WebMercatorProjection.mercatorAngleToGeodeticLatitude` computes it (spherical).
pub fn web_mercator_latitude(y: f64) -> f64 {
    let angle = std::f64::consts::PI * (2.0 * y - 1.0);
    (std::f64::consts::FRAC_PI_2 - 2.0 * (-angle).exp().atan()).to_degrees()
}

/// The Web Mercator `y` of latitude `lat` (degrees), in turns from the south edge (see
/// [`web_mercator_latitude`]): below 0 or above 1 beyond about ±85.0511°.
pub fn web_mercator_y(lat: f64) -> f64 {
    let phi = lat.to_radians();
    let angle = (std::f64::consts::FRAC_PI_4 + phi / 2.0).tan().ln();
    (angle / std::f64::consts::PI + 1.0) / 2.0
}

impl GeoLattice {
    /// The longitude of column `i`: `west + (first_column + i) * step`, the column counted
    /// modulo a turn when `step` divides 360 degrees into whole columns. So a point a turn
    /// east (a window round the globe that runs on past 180°) gets the very position, to
    /// the bit, of the same point in the first turn.
    pub fn lon(&self, i: u32) -> f64 {
        let mut column = self.first_column + u64::from(i);
        let turn = (360.0 / self.step).round();
        if turn >= 1.0 && (turn * self.step - 360.0).abs() <= 1e-9 {
            column %= turn as u64;
        }
        self.west + column as f64 * self.step
    }

    /// The latitude of row `j`: `south + (first_row + j) * step` for uniform rows, else
    /// as [`Latitudes`] places it.
    pub fn lat(&self, j: u32) -> f64 {
        let row = self.first_row + u64::from(j);
        match self.latitudes {
            Latitudes::Uniform => self.south + row as f64 * self.step,
            Latitudes::WebMercatorTiles { cells, tiles } => {
                let cells = u64::from(cells);
                let tile = (row / cells).min(tiles.saturating_sub(1));
                let k = row - tile * cells;
                let south = web_mercator_latitude(tile as f64 / tiles as f64);
                let north = web_mercator_latitude((tile + 1) as f64 / tiles as f64);
                south + (north - south) * (k as f64 / cells as f64)
            }
        }
    }
}

/// WGS84 (EPSG:4326) in longitude, latitude order.
pub(crate) fn wgs84() -> Result<SpatialRef> {
    let mut srs = SpatialRef::from_epsg(4326).expect("PROJ knows EPSG:4326");
    srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    Ok(srs)
}

/// A failure of PROJ (through GDAL) to reproject the raster at `path`.
pub(crate) fn warp_error(path: &Path, source: gdal::errors::GdalError) -> Error {
    Error::Warp {
        path: path.to_path_buf(),
        reason: gdal_reason(&source, path),
        source: Box::new(source),
    }
}

/// The raster's extent in EPSG:4326 (edges densified, so curved edges are covered) and its
/// resolution in degrees.
///
/// # Errors
/// As [`crate::open_info`], [`Error::NotGeoreferenced`] without a CRS or geotransform, and
/// [`Error::Warp`] when PROJ cannot transform the extent.
pub fn geographic_bounds(path: &Path, band: usize) -> Result<GeoBounds> {
    let opened = OpenBand::open(path, band)?;
    let b = raw_bounds(path, &opened)?;
    let (w, h) = samples_across(&opened.info);
    // PROJ gives west > east for an extent across the antimeridian (a projected raster
    // over 180 degrees): count east on past 180 instead.
    let (west, east) = if b[0] > b[2] {
        (b[0], b[2] + 360.0)
    } else {
        (b[0], b[2])
    };
    let resolution = resolution((east - west) / w, (b[3] - b[1]) / h);
    // A global grid's extent can come out a rounding error short of the whole circle
    // (ETOPO5's 5' pixels from -0.041666666667: 3e-13 degrees short); a millionth of a
    // sample is far below any gap a raster could mean.
    let (west, east) = if east - west >= 360.0 - 1e-6 * resolution {
        // The whole circle of longitudes (a global grid, in any frame).
        (-180.0, 180.0)
    } else if west < -180.0 {
        (west + 360.0, east + 360.0)
    } else {
        (west, east)
    };
    Ok(GeoBounds {
        west,
        south: b[1].max(-90.0),
        east,
        north: b[3].min(90.0),
        resolution,
    })
}

/// How many times finer than the geometric mean of a sample's longitude and latitude spans
/// [`GeoBounds::resolution`] may be: a lattice that fine holds at most 64 times the raster's
/// sample count. Pixels up to 64 times wider (in degrees) than tall, as projected rasters
/// have up to about 89° of latitude (or a polar cap of 3600 x 3600 from 80° to the pole),
/// resolve their finer axis; extremely tall or wide ones (a 100000 x 10 global raster is
/// 0.0036° by 18°) would otherwise be resampled onto billions of lattice points.
const MAX_ANISOTROPY: f64 = 8.0;

/// The span per sample a lattice needs for a raster of `lon` by `lat` degrees per sample.
fn resolution(lon: f64, lat: f64) -> f64 {
    lon.min(lat).max((lon * lat).sqrt() / MAX_ANISOTROPY)
}

/// Whether the band's heights may lie beyond `f32`'s range, from its metadata alone: its
/// samples are `Float64`, or a scale or offset could take them there. (The samples on a
/// geographic lattice are `f32`.)
///
/// # Errors
/// As [`crate::open_info`].
pub fn heights_may_exceed_f32(path: &Path, band: usize) -> Result<bool> {
    let info = OpenBand::open(path, band)?.info;
    Ok(info.data_type == "Float64" || info.scale.abs() > 1.0 || info.offset.abs() > 1e30)
}

/// How many samples at the raster's own spacing span its extent's width and height in its
/// CRS: its columns and rows, or more when the geotransform is rotated (the extent is then
/// the box around the rotated raster, wider and taller than its sides).
fn samples_across(info: &RasterInfo) -> (f64, f64) {
    let (w, h) = (f64::from(info.width), f64::from(info.height));
    match info.geo_transform {
        Some(gt) if gt[2] != 0.0 || gt[4] != 0.0 => {
            let spacing = gt[1].hypot(gt[4]).min(gt[2].hypot(gt[5]));
            let span_x = (w * gt[1]).abs() + (h * gt[2]).abs();
            let span_y = (w * gt[4]).abs() + (h * gt[5]).abs();
            (span_x / spacing, span_y / spacing)
        }
        _ => (w, h),
    }
}

/// The raster's geotransform, when it has one and a CRS, and the geotransform is not
/// singular.
///
/// # Errors
/// [`Error::NotGeoreferenced`] otherwise, saying what is missing and how to add it.
pub(crate) fn geo_transform(path: &Path, info: &RasterInfo) -> Result<[f64; 6]> {
    let (Some(gt), Some(_)) = (info.geo_transform, info.crs_wkt.as_ref()) else {
        let (missing, hint) = match (info.geo_transform, &info.crs_wkt) {
            (None, _) if info.gcp_count > 0 => (
                "only ground control points (GCPs), no geotransform",
                "warp it onto a grid in the GCPs' CRS first, e.g. `gdalwarp IN OUT.tif`",
            ),
            (None, _) if info.geolocation => (
                "only geolocation arrays, no geotransform",
                "warp it onto a grid first, e.g. `gdalwarp -geoloc IN OUT.tif`",
            ),
            (Some(_), _) => (
                "no CRS",
                "assign the CRS its coordinates are in, e.g. `gdal_translate -of VRT -a_srs \
                 EPSG:<code> IN OUT.vrt`",
            ),
            (None, Some(_)) => (
                "no geotransform",
                "assign one, e.g. `gdal_translate -of VRT -a_ullr ULX ULY LRX LRY IN OUT.vrt`",
            ),
            (None, None) => (
                "no CRS and no geotransform",
                "assign both, e.g. `gdal_translate -of VRT -a_srs EPSG:<code> -a_ullr ULX ULY \
                 LRX LRY IN OUT.vrt`",
            ),
        };
        return Err(Error::NotGeoreferenced {
            path: path.to_path_buf(),
            missing,
            hint,
        });
    };
    if tinsmith_georef::GeoTransform(gt).is_singular() {
        return Err(Error::NotGeoreferenced {
            path: path.to_path_buf(),
            missing: "a singular geotransform (a pixel size of 0: every sample at one place)",
            hint: "assign a real one, e.g. `gdal_translate -of VRT -a_ullr ULX ULY LRX LRY \
                   IN OUT.vrt`",
        });
    }
    Ok(gt)
}

/// The raster's CRS, x easting or longitude and y northing or latitude.
pub(crate) fn source_crs(path: &Path, opened: &OpenBand) -> Result<SpatialRef> {
    let mut source = opened
        .dataset()
        .spatial_ref()
        .map_err(|e| warp_error(path, e))?;
    source.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    Ok(source)
}

/// The box around the raster's four corners in its own CRS: `[x_min, y_min, x_max, y_max]`
/// (with a rotated geotransform two opposite corners do not bound it).
pub(crate) fn corner_box(gt: &[f64; 6], info: &RasterInfo) -> [f64; 4] {
    let (w, h) = (f64::from(info.width), f64::from(info.height));
    let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)];
    let xs = corners.map(|(c, r)| gt[0] + c * gt[1] + r * gt[2]);
    let ys = corners.map(|(c, r)| gt[3] + c * gt[4] + r * gt[5]);
    let min = |v: [f64; 4]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = |v: [f64; 4]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    [min(xs), min(ys), max(xs), max(ys)]
}

/// The raster's extent in EPSG:4326 as PROJ's area of interest wants it (west and east in
/// -180..180, west > east across the antimeridian), as GDAL's warper sets it so that PROJ
/// picks one transformation for the whole raster; `None` when PROJ cannot give the extent.
pub(crate) fn area_of_interest(path: &Path, opened: &OpenBand) -> Option<[f64; 4]> {
    let [west, south, east, north] = raw_bounds(path, opened).ok()?;
    // Into -180..180, the east edge at 180 (not -180) unless the west one is there too.
    let lon = |v: f64| v - 360.0 * ((v + 180.0) / 360.0).floor();
    let (west, east) = if west <= east && east - west >= 360.0 {
        (-180.0, 180.0)
    } else {
        (lon(west), lon(east))
    };
    let east = if east == -180.0 && west > -180.0 {
        180.0
    } else {
        east
    };
    let aoi = [west, south.max(-90.0), east, north.min(90.0)];
    aoi.iter().all(|v| v.is_finite()).then_some(aoi)
}

/// The raster's extent in EPSG:4326 as PROJ gives it, longitudes not wrapped.
fn raw_bounds(path: &Path, opened: &OpenBand) -> Result<[f64; 4]> {
    let gt = geo_transform(path, &opened.info)?;
    let source = source_crs(path, opened)?;
    let transform = CoordTransform::new(&source, &wgs84()?).map_err(|e| warp_error(path, e))?;
    transform
        .transform_bounds(&corner_box(&gt, &opened.info), 21)
        .map_err(|e| warp_error(path, e))
}
