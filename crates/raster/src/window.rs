//! Windowed reads: a rectangle of one band at a time, through a dataset kept open.

use std::path::Path;

use tinsmith_georef::Samples;

use crate::coverage::coarse_read;
use crate::datum::VerticalDatum;
use crate::error::{Error, Result};
use crate::info::RasterInfo;
use crate::read::OpenBand;

/// Cells a side of [`WindowReader::has_valid_cell`]'s coarse look.
const COARSE_SIDE: usize = 256;

/// Cells with data the coarse look tries before the full scan.
const COARSE_TRIES: usize = 16;

/// The largest side, in samples, of the window read about a coarse cell with data.
const NEAR: u32 = 256;

/// One band of a raster kept open for reading windows of it, one after another.
///
/// The samples of a window are decoded exactly as [`crate::read_samples`] decodes the
/// whole band (the same nodata rule in the band's own type, NaN and infinities as nodata,
/// scale and offset applied), so a window of the samples `read_samples` returns and the
/// samples [`WindowReader::read_window`] returns for the same rectangle are equal sample
/// for sample.
///
/// # Threads
/// A reader owns a GDAL dataset, which may be moved to another thread but not shared
/// between threads (`Send`, not `Sync`). Open one reader per worker thread, for example
/// with rayon's `map_init`.
///
/// # Example
/// ```no_run
/// use std::path::Path;
/// # fn main() -> Result<(), tinsmith_raster::Error> {
/// let reader = tinsmith_raster::WindowReader::open(Path::new("data/becmodel_dem_bc_albers_50m.tif"), 1)?;
/// let tile = reader.read_window(100, 200, 64, 64)?;
/// assert_eq!((tile.width(), tile.height()), (64, 64));
/// # Ok(())
/// # }
/// ```
pub struct WindowReader {
    opened: OpenBand,
}

impl std::fmt::Debug for WindowReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WindowReader")
            .field("path", &self.opened.info.path)
            .field("band", &self.opened.info.band)
            .finish_non_exhaustive()
    }
}

impl WindowReader {
    /// Opens band `band` (1-based) of the raster at `path` without reading any sample.
    ///
    /// # Errors
    /// [`Error::NotFound`], [`Error::NotARaster`], [`Error::BandOutOfRange`],
    /// [`Error::UnsupportedType`] and [`Error::Read`], each naming `path`.
    pub fn open(path: &Path, band: usize) -> Result<WindowReader> {
        WindowReader::open_on(path, band, &VerticalDatum::Ellipsoid)
    }

    /// [`WindowReader::open`], reading heights above `datum` as heights above the WGS84
    /// ellipsoid, sample for sample as [`crate::read_samples_on`] reads them (the reader's
    /// [`RasterInfo::converted_from`] says so).
    ///
    /// # Errors
    /// As [`WindowReader::open`], plus [`Error::VerticalDatum`] as
    /// [`crate::read_samples_on`].
    pub fn open_on(path: &Path, band: usize, datum: &VerticalDatum) -> Result<WindowReader> {
        Ok(WindowReader {
            opened: OpenBand::open(path, band)?.converting(datum)?,
        })
    }

    /// The band's metadata. No sample has been read, so the statistics are those of an
    /// empty band: `valid_samples` and `nodata_samples` are 0, `min` and `max` are `None`
    /// (use [`crate::open_info`] for them).
    pub fn info(&self) -> &RasterInfo {
        &self.opened.info
    }

    /// Columns of the raster.
    pub fn width(&self) -> u32 {
        self.opened.info.width
    }

    /// Rows of the raster.
    pub fn height(&self) -> u32 {
        self.opened.info.height
    }

    /// Reads the `width` x `height` samples whose top-left sample is column `x0`, row `y0`
    /// into [`Samples`] (their row 0 is row `y0` of the raster; nodata as NaN).
    ///
    /// A window without any valid sample is not an error: every sample is NaN.
    ///
    /// # Errors
    /// [`Error::WindowOutOfRange`] when the window is empty or not inside the raster,
    /// [`Error::TooLarge`] when it has 2^32 - 1 samples or more, [`Error::Read`] when GDAL
    /// fails.
    pub fn read_window(&self, x0: u32, y0: u32, width: u32, height: u32) -> Result<Samples> {
        let info = &self.opened.info;
        let inside = |start: u32, len: u32, total: u32| {
            len > 0 && start.checked_add(len).is_some_and(|end| end <= total)
        };
        if !inside(x0, width, info.width) || !inside(y0, height, info.height) {
            return Err(Error::WindowOutOfRange {
                path: info.path.clone(),
                x0,
                y0,
                width,
                height,
                raster_width: info.width,
                raster_height: info.height,
            });
        }
        let samples = width as u64 * height as u64;
        if samples >= u32::MAX as u64 {
            return Err(Error::TooLarge {
                path: info.path.clone(),
                width: width as usize,
                height: height as usize,
            });
        }
        let rb = self.opened.band()?;
        let mut values = vec![0.0; samples as usize];
        self.opened.read_window(
            &rb,
            (x0 as usize, y0 as usize),
            (width as usize, height as usize),
            &mut values,
        )?;
        Samples::new(width, height, values).map_err(|source| Error::Grid {
            path: info.path.clone(),
            band: info.band,
            source,
        })
    }

    /// The samples at the given `columns` and `rows` (each strictly increasing, inside the
    /// raster), row-major over `rows` x `columns`, decoded as [`WindowReader::read_window`]
    /// decodes them: a sparse lattice of a raster too large to hold, such as the samples
    /// a picture shows. The band is read block by block, each block once, and GDAL's cache
    /// is emptied after each row of blocks, so memory is the result, one block and one
    /// row of blocks in GDAL's cache, whatever the raster's size.
    ///
    /// # Errors
    /// [`Error::WindowOutOfRange`] when `columns` or `rows` is not strictly increasing
    /// inside the raster, [`Error::Read`] when GDAL fails.
    pub fn read_lattice(&mut self, columns: &[u32], rows: &[u32]) -> Result<Vec<f64>> {
        let (width, height) = (self.width(), self.height());
        let increasing = |picked: &[u32], side: u32| {
            picked.windows(2).all(|w| w[0] < w[1]) && picked.last().is_none_or(|&l| l < side)
        };
        if !increasing(columns, width) || !increasing(rows, height) {
            return Err(Error::WindowOutOfRange {
                path: self.opened.info.path.clone(),
                x0: columns.first().copied().unwrap_or(0),
                y0: rows.first().copied().unwrap_or(0),
                width: columns.len() as u32,
                height: rows.len() as u32,
                raster_width: width,
                raster_height: height,
            });
        }
        let (block_width, block_height) = {
            let (w, h) = self.opened.band()?.block_size();
            (w.max(1) as u32, h.max(1) as u32)
        };
        let mut out = vec![f64::NAN; columns.len() * rows.len()];
        // The picked indices in `picked` that fall in [start, start + len).
        let within = |picked: &[u32], start: u32, len: u32| {
            let lo = picked.partition_point(|&p| p < start);
            let hi = picked.partition_point(|&p| p < start.saturating_add(len));
            lo..hi
        };
        let mut block_row = 0;
        while block_row < height {
            let band_rows = within(rows, block_row, block_height);
            if !band_rows.is_empty() {
                let (y0, y1) = (rows[band_rows.start], rows[band_rows.end - 1]);
                let mut block_column = 0;
                while block_column < width {
                    let band_columns = within(columns, block_column, block_width);
                    if !band_columns.is_empty() {
                        let (x0, x1) = (columns[band_columns.start], columns[band_columns.end - 1]);
                        let window = self.read_window(x0, y0, x1 - x0 + 1, y1 - y0 + 1)?;
                        let values = window.values();
                        let stride = (x1 - x0 + 1) as usize;
                        for j in band_rows.clone() {
                            let from = (rows[j] - y0) as usize * stride;
                            for i in band_columns.clone() {
                                out[j * columns.len() + i] =
                                    values[from + (columns[i] - x0) as usize];
                            }
                        }
                    }
                    block_column = block_column.saturating_add(block_width);
                }
                self.opened.release_cached_blocks()?;
            }
            block_row = block_row.saturating_add(block_height);
        }
        Ok(out)
    }

    /// Whether the band has a 2x2 block of valid samples (a cell a TIN can cover).
    ///
    /// The band is scanned in bands of whole rows (about 2^20 samples, sharing a row),
    /// stopping at the first such block; but when the first band has none, a coarse look
    /// comes before the rest of the scan (at most 256 cells a side, from overviews where
    /// the file has them): around each of the first few cells with data, a small window
    /// at full resolution, which usually holds such a block. So the answer is exact, and
    /// quick for a raster with data, even one whose first rows are all nodata (a land DEM
    /// of the globe starts with the Arctic Ocean).
    ///
    /// # Errors
    /// As [`WindowReader::read_window`].
    pub fn has_valid_cell(&self) -> Result<bool> {
        let (width, height) = (self.width(), self.height());
        if width < 2 || height < 2 {
            return Ok(false);
        }
        let rows = ((1u32 << 20) / width).clamp(2, height);
        let mut y0 = 0;
        loop {
            let band = rows.min(height - y0);
            if self.read_window(0, y0, width, band)?.valid_cell_count() > 0 {
                return Ok(true);
            }
            if y0 + band >= height {
                return Ok(false);
            }
            if y0 == 0 && self.valid_cell_near_coarse_data()? {
                return Ok(true);
            }
            // The next band starts on this one's last row: no cell is skipped.
            y0 += band - 1;
        }
    }

    /// Whether a window about one of the first cells with data of a coarse look at the
    /// band holds a 2x2 block of valid samples (see [`WindowReader::has_valid_cell`]).
    fn valid_cell_near_coarse_data(&self) -> Result<bool> {
        let (width, height) = (self.width(), self.height());
        let coarse = coarse_read(&self.opened, COARSE_SIDE)?;
        let hits = coarse
            .values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite());
        for (k, _) in hits.take(COARSE_TRIES) {
            let (i, j) = (k % coarse.width, k / coarse.width);
            // The sample GDAL picked for the cell lies within it: the window is the cell,
            // at most `NEAR` samples a side about its centre, at least 2.
            let (cx, cy) = (
                (i as f64 + 0.5) * coarse.cell.0,
                (j as f64 + 0.5) * coarse.cell.1,
            );
            let span = |cell: f64, total: u32| (cell.ceil() as u32).clamp(2, NEAR).min(total);
            let (w, h) = (span(coarse.cell.0, width), span(coarse.cell.1, height));
            let start = |centre: f64, len: u32, total: u32| {
                ((centre - f64::from(len) / 2.0).max(0.0) as u32).min(total - len)
            };
            let (x0, y0) = (start(cx, w, width), start(cy, h, height));
            if self.read_window(x0, y0, w, h)?.valid_cell_count() > 0 {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// Reads one window of band `band` (1-based) of the raster at `path`: opens the raster,
/// reads as [`WindowReader::read_window`], closes it. To read many windows, keep a
/// [`WindowReader`] open instead.
///
/// # Errors
/// As [`WindowReader::open`] and [`WindowReader::read_window`].
pub fn read_window(
    path: &Path,
    band: usize,
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
) -> Result<Samples> {
    WindowReader::open(path, band)?.read_window(x0, y0, width, height)
}
