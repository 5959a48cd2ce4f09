//! Tiles read from a raster file through GDAL, one dataset per worker thread (the `raster`
//! feature).

use std::path::{Path, PathBuf};

use tinsmith_georef::Samples;
use tinsmith_raster::{RasterInfo, VerticalDatum, WindowReader};

use crate::error::{Error, Result};
use crate::source::{ReadError, TileSource, WindowRead};

/// One band of a raster file, read through GDAL, a window at a time.
///
/// Samples are decoded as `tinsmith_raster::read_samples` decodes them (nodata compared in
/// the band's own type, NaN and infinities as nodata, scale and offset applied).
#[derive(Debug, Clone)]
pub struct RasterSource {
    path: PathBuf,
    band: usize,
    width: u32,
    height: u32,
    max_abs_value: f64,
    integral_heights: bool,
    /// The datum whose heights the readers turn into ellipsoidal ones, as `info` was read.
    converted_from: Option<VerticalDatum>,
}

impl RasterSource {
    /// The band described by `info`, which must come from `tinsmith_raster::open_info` or
    /// `open_info_on` (it has the statistics the raster-wide max |value| comes from);
    /// windows are read as `info` was (heights converted from its `converted_from` datum).
    ///
    /// # Errors
    /// [`Error::AllNodata`] when the band has no valid sample.
    pub fn new(info: &RasterInfo) -> Result<RasterSource> {
        let max_abs_value = info.max_abs_value().ok_or_else(|| Error::AllNodata {
            path: info.path.clone(),
            band: info.band,
        })?;
        Ok(RasterSource {
            path: info.path.clone(),
            band: info.band,
            width: info.width,
            height: info.height,
            max_abs_value,
            integral_heights: info.integral_heights,
            converted_from: info.converted_from.clone(),
        })
    }

    /// Opens band `band` (1-based) of the raster at `path` and scans it once for its
    /// statistics (`tinsmith_raster::open_info`), strip by strip: memory stays small.
    ///
    /// # Errors
    /// [`Error::Raster`] as `open_info`; [`Error::AllNodata`].
    pub fn open(path: &Path, band: usize) -> Result<RasterSource> {
        RasterSource::new(&tinsmith_raster::open_info(path, band)?)
    }

    /// The raster file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The band (1-based).
    pub fn band(&self) -> usize {
        self.band
    }
}

impl TileSource for RasterSource {
    type Reader = WindowReader;

    fn width(&self) -> u32 {
        self.width
    }

    fn height(&self) -> u32 {
        self.height
    }

    fn max_abs_value(&self) -> f64 {
        self.max_abs_value
    }

    fn integral_heights(&self) -> bool {
        self.integral_heights
    }

    fn reader(&self) -> std::result::Result<WindowReader, ReadError> {
        let datum = self.converted_from.as_ref();
        let datum = datum.unwrap_or(&VerticalDatum::Ellipsoid);
        Ok(WindowReader::open_on(&self.path, self.band, datum)?)
    }
}

impl WindowRead for WindowReader {
    fn read_window(
        &mut self,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        Ok(WindowReader::read_window(self, x0, y0, width, height)?)
    }
}
