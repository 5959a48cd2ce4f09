//! Reprojection to EPSG:4326: a raster's geographic bounds, and its samples on a regular
//! longitude/latitude lattice through GDAL's warper.

use std::path::Path;

use gdal::raster::reproject;
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use gdal::{Dataset, DriverManager};

use crate::error::{gdal_reason, Error, Result};
use crate::info::RasterInfo;
use crate::read::{MaskSource, OpenBand};

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

/// A regular lattice of sample positions in EPSG:4326: column `i`, row `j` is at longitude
/// `west + i * step`, latitude `south + j * step` (row 0 is the southernmost).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoLattice {
    /// Longitude of column 0.
    pub west: f64,
    /// Latitude of row 0.
    pub south: f64,
    /// Spacing in degrees.
    pub step: f64,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

fn wgs84() -> Result<SpatialRef> {
    let mut srs = SpatialRef::from_epsg(4326).expect("PROJ knows EPSG:4326");
    srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    Ok(srs)
}

fn warp_error(path: &Path, source: gdal::errors::GdalError) -> Error {
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
/// samples are `Float64`, or a scale or offset could take them there. (The warp to
/// geographic coordinates works in `f32`.)
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

/// The raster's extent in EPSG:4326 as PROJ gives it, longitudes not wrapped.
fn raw_bounds(path: &Path, opened: &OpenBand) -> Result<[f64; 4]> {
    let info = &opened.info;
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
    let (w, h) = (f64::from(info.width), f64::from(info.height));
    // All four corners: with a rotated geotransform two opposite ones do not bound it.
    let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)];
    let xs = corners.map(|(c, r)| gt[0] + c * gt[1] + r * gt[2]);
    let ys = corners.map(|(c, r)| gt[3] + c * gt[4] + r * gt[5]);
    let (x_min, x_max) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let (y_min, y_max) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min),
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let mut source = opened
        .dataset()
        .spatial_ref()
        .map_err(|e| warp_error(path, e))?;
    source.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let transform = CoordTransform::new(&source, &wgs84()?).map_err(|e| warp_error(path, e))?;
    transform
        .transform_bounds(&[x_min, y_min, x_max, y_max], 21)
        .map_err(|e| warp_error(path, e))
}

/// The band's samples at the lattice's positions, reprojected by GDAL's warper (bilinear,
/// the band's nodata honoured), with the band's scale and offset applied: row-major, row 0
/// the southernmost, NaN where there is no data.
///
/// # Errors
/// As [`geographic_bounds`].
pub fn warp_to_geographic(path: &Path, band: usize, lattice: &GeoLattice) -> Result<Vec<f32>> {
    let opened = OpenBand::open(path, band)?;
    let b = raw_bounds(path, &opened)?;
    let roll = global_roll(&opened);
    let view = band_view(path, &opened, roll)?;
    let mut values = warp_pass(path, &opened, &view, lattice, 0.0)?;
    // Sources in 0..360 (or -360..0) longitudes: the part beyond the antimeridian is
    // warped again with the lattice shifted by a full turn, filling what is still empty.
    // A rolled global view is already in -180..180 and whole.
    let shifts: &[f64] = if roll.is_some() {
        &[]
    } else {
        &[360.0, -360.0]
    };
    for &shift in shifts {
        let beyond = if shift > 0.0 {
            b[2] > 180.0
        } else {
            b[0] < -180.0
        };
        if beyond && values.iter().any(|v| v.is_nan()) {
            let more = warp_pass(path, &opened, &view, lattice, shift)?;
            for (v, m) in values.iter_mut().zip(more) {
                if v.is_nan() {
                    *v = m;
                }
            }
        }
    }
    Ok(values)
}

/// How a geographic raster covering the whole circle from about 0° (0..360°, or -360..0°)
/// is rolled into -180..180°: its first `columns` columns (one turn; a repeated last column is left
/// out), the part from column `split` (the first whose centre is at or past 180°) moved a
/// turn west in front of the rest. `None` for any other raster.
///
/// GDAL's warper sees such a raster's 0° meridian as an edge: lattice samples within half
/// a pixel west of it got the edge value, not the bilinear one across it, and a warp chunk
/// reaching past the edge computed its resampling scale from the part with data, blurring
/// up to a chunk's width on either side (ETOPO5 at level 4: up to 2.8 km off at La Palma).
/// Rolled, the raster is seamless there, as one stored in -180..180° is.
#[derive(Debug, Clone, Copy, PartialEq)]
struct GlobalRoll {
    split: usize,
    columns: usize,
    /// The raster's west edge moved by whole turns into -180..180° (a raster on -360..0°
    /// rolls as one on 0..360°).
    west: f64,
}

/// Columns repeated from the far side on each side of a rolled view, so that bilinear
/// samples next to ±180° have both neighbours.
const ROLL_MARGIN: usize = 1;

impl GlobalRoll {
    /// The view's columns.
    fn width(self) -> usize {
        self.columns + 2 * ROLL_MARGIN
    }

    /// How far the view's column 0 is east of the raster's, in columns (negative: west).
    fn offset(self) -> f64 {
        self.split as f64 - self.columns as f64 - ROLL_MARGIN as f64
    }

    /// The view's pieces as (raster column, view column, columns): the last columns before
    /// the split (a margin), the part from the split, the part before it, then the first
    /// columns from the split again (a margin).
    fn pieces(self) -> [(usize, usize, usize); 4] {
        let (m, split, east) = (ROLL_MARGIN, self.split, self.columns - self.split);
        [
            (split - m, 0, m),
            (split, m, east),
            (0, m + east, split),
            (split, m + self.columns, m),
        ]
    }
}

fn global_roll(opened: &OpenBand) -> Option<GlobalRoll> {
    let info = &opened.info;
    let gt = info.geo_transform?;
    let geographic = info
        .crs_wkt
        .as_deref()
        .is_some_and(|wkt| crate::is_geographic(wkt).unwrap_or(false));
    if !geographic || gt[2] != 0.0 || gt[4] != 0.0 || gt[1].is_nan() || gt[1] <= 0.0 {
        return None;
    }
    let turn = 360.0 / gt[1];
    let columns = turn.round();
    let width = f64::from(info.width);
    // One whole turn of columns (to a millionth of a pixel), within the raster, starting
    // west of 180 and reaching past it.
    if (turn - columns).abs() > 1e-6 || columns < 2.0 || columns > width {
        return None;
    }
    let west = gt[0] - 360.0 * ((gt[0] + 180.0) / 360.0).floor();
    let split = ((180.0 - west) / gt[1] - 0.5).ceil();
    let margin = ROLL_MARGIN as f64;
    if split.is_nan() || split < margin || split + margin > columns {
        return None;
    }
    Some(GlobalRoll {
        split: split as usize,
        columns: columns as usize,
        west,
    })
}

/// `xml` with its one source element (`SimpleSource` or `ComplexSource`) placed as `roll`
/// says (see [`GlobalRoll::pieces`]). Unchanged without a roll.
fn rolled(xml: &str, roll: Option<GlobalRoll>, height: u32) -> String {
    let Some(roll) = roll else {
        return xml.to_owned();
    };
    for tag in ["SimpleSource", "ComplexSource"] {
        let close = format!("</{tag}>");
        if let (Some(start), Some(end)) = (xml.find(&format!("<{tag}>")), xml.find(&close)) {
            let element = &xml[start..end];
            let placed: String = roll
                .pieces()
                .iter()
                .map(|&(from, to, width)| {
                    format!(
                        "{element}<SrcRect xOff=\"{from}\" yOff=\"0\" xSize=\"{width}\" \
                         ySize=\"{height}\"/><DstRect xOff=\"{to}\" yOff=\"0\" \
                         xSize=\"{width}\" ySize=\"{height}\"/>{close}"
                    )
                })
                .collect();
            return format!("{}{placed}{}", &xml[..start], &xml[end + close.len()..]);
        }
    }
    xml.to_owned()
}

/// The band alone, as GDAL's warper must see it: an in-memory VRT whose band 1 is the
/// band (GDALReprojectImage warps band 1 of its source, whatever band was asked for), and
/// whose band 2, when the band has a mask (a mask band, or an alpha band of any type), is
/// that mask as an alpha band of 0 and 255 (nonzero is valid, as the reader has it), which
/// the warper honours.
///
/// A float band's nodata is NaN in the view, its declared nodata value (if any) turned into
/// NaN as well, and masked by GDAL's nodata mask too (which has GDAL's tolerance): the
/// warper takes one nodata value, and a NaN it did not know as nodata would be blended
/// into its valid neighbours. An integer band keeps its nodata value,
/// written as an integer (GDAL reads an Int64 nodata with `strtoll`).
fn band_view(path: &Path, opened: &OpenBand, roll: Option<GlobalRoll>) -> Result<Dataset> {
    let info = &opened.info;
    let escape = |text: &str| {
        text.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
    };
    let source = escape(&path.to_string_lossy());
    let rb = opened.band()?;
    let gdal_type = rb.band_type().name();
    let file = format!("<SourceFilename relativeToVRT=\"0\">{source}</SourceFilename>");
    let band = if gdal_type.starts_with("Float") {
        match info.nodata {
            // Where the source equals NODATA the view keeps its initial value, NaN.
            Some(v) if !v.is_nan() => format!(
                "<NoDataValue>nan</NoDataValue><ComplexSource>{file}<SourceBand>{}</SourceBand>\
                 <NODATA>{v:?}</NODATA></ComplexSource>",
                info.band
            ),
            // Nothing to turn into NaN: a simple source gives the same values, and GDAL
            // copies it without the complex source's per-sample pass in f64 (which took
            // most of a coarse level's warp from a large raster).
            _ => format!(
                "<NoDataValue>nan</NoDataValue><SimpleSource>{file}<SourceBand>{}</SourceBand>\
                 </SimpleSource>",
                info.band
            ),
        }
    } else {
        // Exactly, for the 64-bit types too (beyond 2^53 the f64 in `info` is rounded).
        let nodata = match (gdal_type.as_str(), info.nodata) {
            ("Int64", _) => rb.no_data_value_i64().map(|v| v.to_string()),
            ("UInt64", _) => rb.no_data_value_u64().map(|v| v.to_string()),
            // A fractional nodata matches no sample of an integer band (as the reader has it).
            (_, Some(v)) if v.fract() != 0.0 => None,
            (_, Some(v)) if v < 0.0 => Some((v as i64).to_string()),
            (_, Some(v)) => Some((v as u64).to_string()),
            (_, None) => None,
        };
        let nodata = nodata.map_or(String::new(), |v| format!("<NoDataValue>{v}</NoDataValue>"));
        format!(
            "{nodata}<SimpleSource>{file}<SourceBand>{}</SourceBand></SimpleSource>",
            info.band
        )
    };
    let band = rolled(&band, roll, info.height);
    let (width, geo_transform) = match (roll, info.geo_transform) {
        (Some(r), Some(mut g)) => {
            // The raster's column `split` is a turn west of where it was: `columns` columns.
            g[0] = r.west + r.offset() * g[1];
            (r.width() as u32, Some(g))
        }
        _ => (info.width, info.geo_transform),
    };
    let gt = geo_transform
        .map(|g| g.map(|v| format!("{v:?}")).join(","))
        .unwrap_or_default();
    let srs = info.crs_wkt.as_deref().map(escape).unwrap_or_default();
    let mask_band = match opened.mask_source {
        // GDAL's nodata mask compares in the band's type with its tolerance (a Float32
        // nodata of -3.4e38 masks -FLT_MAX samples, as the reader does); NODATA above
        // compares in f64, exactly.
        None if gdal_type.starts_with("Float") && info.nodata.is_some_and(|v| !v.is_nan()) => {
            Some(format!("mask,{}", info.band))
        }
        None => None,
        Some(MaskSource::Gdal(_)) => Some(format!("mask,{}", info.band)),
        Some(MaskSource::Alpha(b)) => Some(b.to_string()),
    };
    // Any nonzero value is valid: 0 stays 0, everything else (negative too) becomes 255.
    let alpha = mask_band.map_or(String::new(), |mask| {
        let source = rolled(
            &format!(
                "<ComplexSource>{file}<SourceBand>{mask}</SourceBand>\
                 <LUT>-1.7976931348623157e308:255,-5e-324:255,0:0,5e-324:255</LUT>\
                 </ComplexSource>"
            ),
            roll,
            info.height,
        );
        format!(
            "<VRTRasterBand dataType=\"Byte\" band=\"2\"><ColorInterp>Alpha</ColorInterp>\
             {source}</VRTRasterBand>"
        )
    });
    let xml = format!(
        "<VRTDataset rasterXSize=\"{width}\" rasterYSize=\"{}\"><SRS>{srs}</SRS>\
         <GeoTransform>{gt}</GeoTransform><VRTRasterBand dataType=\"{gdal_type}\" band=\"1\">\
         {band}</VRTRasterBand>{alpha}</VRTDataset>",
        info.height
    );
    crate::quiet::silence_hdf5_on_this_thread();
    Dataset::open(Path::new(&xml)).map_err(|e| warp_error(path, e))
}

fn warp_pass(
    path: &Path,
    opened: &OpenBand,
    view: &Dataset,
    lattice: &GeoLattice,
    shift: f64,
) -> Result<Vec<f32>> {
    let info = &opened.info;
    let (width, height) = (lattice.width as usize, lattice.height as usize);
    let driver = DriverManager::get_driver_by_name("MEM").map_err(|e| warp_error(path, e))?;
    let mut target = driver
        .create_with_band_type::<f32, _>("", width, height, 1)
        .map_err(|e| warp_error(path, e))?;
    let d = lattice.step;
    let north = lattice.south + (height as f64 - 1.0) * d;
    let west = lattice.west + shift;
    target
        .set_geo_transform(&[west - d / 2.0, d, 0.0, north + d / 2.0, 0.0, -d])
        .map_err(|e| warp_error(path, e))?;
    target
        .set_spatial_ref(&wgs84()?)
        .map_err(|e| warp_error(path, e))?;
    {
        let mut rb = target.rasterband(1).map_err(|e| warp_error(path, e))?;
        rb.set_no_data_value(Some(f64::NAN))
            .map_err(|e| warp_error(path, e))?;
        rb.fill(f64::NAN, None).map_err(|e| warp_error(path, e))?;
    }
    reproject(view, &target).map_err(|e| warp_error(path, e))?;
    let buffer = target
        .rasterband(1)
        .and_then(|rb| rb.read_as::<f32>((0, 0), (width, height), (width, height), None))
        .map_err(|e| warp_error(path, e))?;
    drop(target);
    let (_, mut values) = buffer.into_shape_and_vec();
    // GDAL's row 0 is the northernmost; the lattice's is the southernmost.
    for row in 0..height / 2 {
        let (south, north) = values.split_at_mut((height - 1 - row) * width);
        south[row * width..(row + 1) * width].swap_with_slice(&mut north[..width]);
    }
    let (scale, offset) = (info.scale as f32, info.offset as f32);
    let nodata = info.nodata.map(|v| v as f32);
    for v in &mut values {
        *v = if !v.is_finite() || Some(*v) == nodata {
            f32::NAN
        } else {
            *v * scale + offset
        };
    }
    Ok(values)
}
