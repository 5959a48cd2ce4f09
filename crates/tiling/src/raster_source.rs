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
/// the band's own type, NaN and infinities as nodata, scale and offset applied). Further
/// bands on the same grid may come with it as variables ([`RasterSource::with_variable`]).
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
    /// Each variable's file, band and max |value|.
    variables: Vec<(PathBuf, usize, f64)>,
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
            variables: Vec::new(),
        })
    }

    /// The source with one more variable: the band described by `info` (from
    /// `tinsmith_raster::open_info`, for its statistics), read as it is (no datum
    /// conversion). It must be on the height's grid: the caller checks that; windows of
    /// the same pixel coordinates are read.
    ///
    /// # Errors
    /// [`Error::AllNodata`] when the band has no valid sample.
    pub fn with_variable(mut self, info: &RasterInfo) -> Result<RasterSource> {
        let max_abs_value = info.max_abs_value().ok_or_else(|| Error::AllNodata {
            path: info.path.clone(),
            band: info.band,
        })?;
        self.variables
            .push((info.path.clone(), info.band, max_abs_value));
        Ok(self)
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

/// The readers of one worker thread: the height's band and each variable's.
#[derive(Debug)]
pub struct RasterReader {
    height: WindowReader,
    variables: Vec<WindowReader>,
}

impl TileSource for RasterSource {
    type Reader = RasterReader;

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

    fn variable_count(&self) -> usize {
        self.variables.len()
    }

    fn variable_max_abs_value(&self, k: usize) -> f64 {
        self.variables[k].2
    }

    fn reader(&self) -> std::result::Result<RasterReader, ReadError> {
        let datum = self.converted_from.as_ref();
        let datum = datum.unwrap_or(&VerticalDatum::Ellipsoid);
        Ok(RasterReader {
            height: WindowReader::open_on(&self.path, self.band, datum)?,
            variables: (self.variables.iter())
                .map(|(path, band, _)| WindowReader::open(path, *band))
                .collect::<std::result::Result<_, _>>()?,
        })
    }
}

impl WindowRead for RasterReader {
    fn read_window(
        &mut self,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        Ok(self.height.read_window(x0, y0, width, height)?)
    }

    fn read_variable_window(
        &mut self,
        k: usize,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        match self.variables.get_mut(k) {
            Some(reader) => Ok(reader.read_window(x0, y0, width, height)?),
            None => Err(format!("no variable {k}").into()),
        }
    }
}
