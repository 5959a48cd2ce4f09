//! What a raster band is: its metadata and the statistics of its samples.

use std::path::PathBuf;

use tinsmith_georef::{GeoTransform, Samples};

use crate::datum::VerticalDatum;

/// Metadata of one band of a raster file, plus statistics over its samples.
///
/// Serialises with serde (for `--json` style output). A NaN nodata value serialises as
/// `null` in JSON, like a missing one; [`RasterInfo::nodata`] itself tells them apart.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct RasterInfo {
    /// The path the raster was opened from.
    pub path: PathBuf,
    /// GDAL's short driver name, such as `GTiff`, `AAIGrid` or `PNG`.
    pub driver: String,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Number of bands in the file.
    pub band_count: usize,
    /// The band described here (1-based).
    pub band: usize,
    /// GDAL's name of the band's data type (`Byte`, `Int16`, `Float32`, ...). A Byte band
    /// marked `PIXELTYPE=SIGNEDBYTE` is reported as `Int8`.
    pub data_type: String,
    /// The band's description (GDAL's, e.g. a GeoTIFF band name), when it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The band's declared nodata value, as GDAL reports it (before scale and offset). In
    /// JSON a number, or `"NaN"`, `"inf"`, `"-inf"` (JSON numbers cannot be those), or
    /// `null` when none is declared.
    #[serde(serialize_with = "nodata_json")]
    pub nodata: Option<f64>,
    /// The band's scale: heights are `sample * scale + offset` (1 when the band has none).
    pub scale: f64,
    /// The band's offset (0 when the band has none).
    pub offset: f64,
    /// The dataset's coordinate reference system as WKT, if it has one.
    pub crs_wkt: Option<String>,
    /// The EPSG code of the CRS when it has one or GDAL can identify one; `None` otherwise
    /// (for example for a compound CRS named "unknown").
    pub epsg: Option<u32>,
    /// The dataset's geotransform (GDAL's six coefficients), or `None` when the dataset has
    /// none (GDAL then reports a failure and an identity default, which is not returned).
    pub geo_transform: Option<[f64; 6]>,
    /// How many ground control points (GCPs) the dataset has. tinsmith does not georeference
    /// by them: a raster placed only by GCPs is in pixel coordinates until it is warped.
    pub gcp_count: usize,
    /// Whether the dataset is placed by geolocation arrays (GDAL's `GEOLOCATION` metadata,
    /// as netCDF swaths have), which tinsmith does not use either.
    pub geolocation: bool,
    /// The kind of GDAL mask the band has besides its nodata value (`"alpha band"`,
    /// `"per-dataset mask"` or `"mask band"`), whose zero samples count as nodata; `None`
    /// when it has none.
    pub mask: Option<String>,
    /// Samples that are not nodata.
    pub valid_samples: u64,
    /// Samples that are nodata: equal to [`RasterInfo::nodata`] in the band's type, NaN or
    /// infinite. `valid_samples + nodata_samples == width * height`.
    pub nodata_samples: u64,
    /// Smallest valid height (after scale and offset); `None` when no sample is valid.
    pub min: Option<f64>,
    /// Largest valid height (after scale and offset); `None` when no sample is valid.
    pub max: Option<f64>,
    /// Whether every valid height (after scale and offset) is an integer, as in most DEMs:
    /// an error of 0 can then be decided exactly (see
    /// `tinsmith_core::Grid::integral_heights`). `false` when the statistics were not
    /// computed.
    pub integral_heights: bool,
    /// `Some(datum)` when the heights were read as heights above the WGS84 ellipsoid,
    /// turned from heights above `datum` (a geoid) at every sample; `None` when they are
    /// the band's own values. Readers opened from this info read them the same way.
    #[serde(skip)]
    pub converted_from: Option<VerticalDatum>,
}

impl RasterInfo {
    /// The geotransform as [`GeoTransform`], if the dataset has one.
    pub fn transform(&self) -> Option<GeoTransform> {
        self.geo_transform.map(GeoTransform)
    }

    /// The largest |height| of any valid sample, from [`RasterInfo::min`] and
    /// [`RasterInfo::max`]; `None` when no sample is valid (or the statistics were not
    /// computed, as for [`crate::WindowReader::info`]).
    ///
    /// Tiles of one raster decimated separately all use this value for the rounding slack
    /// (`tinsmith_core::DecimationOptions::max_abs_value`), so that they enforce the same
    /// limit.
    pub fn max_abs_value(&self) -> Option<f64> {
        Some(self.min?.abs().max(self.max?.abs()))
    }
}

/// A band read into [`Samples`] (nodata as NaN), with its [`RasterInfo`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Raster {
    /// The band's heights, row 0 first; nodata samples are NaN, all others finite.
    pub samples: Samples,
    /// What was read, with statistics matching `samples`.
    pub info: RasterInfo,
}

/// [`RasterInfo::nodata`] in JSON: non-finite values as strings, so a NaN nodata is not
/// `null` (which means none).
fn nodata_json<S: serde::Serializer>(nodata: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match nodata {
        None => s.serialize_none(),
        Some(v) if v.is_nan() => s.serialize_str("NaN"),
        Some(v) if v.is_infinite() => s.serialize_str(if *v > 0.0 { "inf" } else { "-inf" }),
        Some(v) => s.serialize_f64(*v),
    }
}
