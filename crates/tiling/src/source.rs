//! Where tiles' samples come from: a grid in memory, or (`raster_source`) a raster file
//! through GDAL.

use tinsmith_core::Grid;
use tinsmith_georef::Samples;

/// What reading a window may fail with: any error, boxed (the engine adds the tile).
pub type ReadError = Box<dyn std::error::Error + Send + Sync>;

/// A raster the engine cuts into tiles.
///
/// The engine asks each worker thread for its own [`TileSource::Reader`] (once per
/// thread), so a reader may hold things that cannot be shared between threads, such as a
/// GDAL dataset.
pub trait TileSource: Sync {
    /// Reads windows on one thread.
    type Reader: WindowRead;

    /// Columns of the raster.
    fn width(&self) -> u32;

    /// Rows of the raster.
    fn height(&self) -> u32;

    /// The largest |value| of any valid sample of the whole raster: every tile's rounding
    /// slack is computed from it, so that all tiles and the shared edges enforce the same
    /// limit.
    fn max_abs_value(&self) -> f64;

    /// Whether every valid sample of the whole raster is an integer: at a bound of 0 the
    /// shared edges then skip exactly collinear samples, as the tiles' cores, measuring
    /// errors of 0 exactly, accept (see `tinsmith_core::Grid::integral_heights`). `false`
    /// (every edge sample kept at a bound of 0) when not known.
    fn integral_heights(&self) -> bool {
        false
    }

    /// How many variables (further bands on the same grid) the source has besides the
    /// height: each tile reads its window of each ([`WindowRead::read_variable_window`]).
    /// 0 unless the source says otherwise.
    fn variable_count(&self) -> usize {
        0
    }

    /// The largest |value| of any valid sample of variable `k` over the whole raster: the
    /// shared edges' limit for that variable is computed from it (see
    /// [`crate::edge_limit`]).
    fn variable_max_abs_value(&self, _k: usize) -> f64 {
        0.0
    }

    /// A reader for the calling thread.
    ///
    /// # Errors
    /// When the raster cannot be opened.
    fn reader(&self) -> std::result::Result<Self::Reader, ReadError>;
}

/// Reads rectangles of a raster.
pub trait WindowRead {
    /// The `width` x `height` samples whose top-left sample is `(x0, y0)`, NaN = nodata.
    /// The engine only asks for windows inside the raster.
    ///
    /// # Errors
    /// When reading fails.
    fn read_window(
        &mut self,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError>;

    /// The same window of variable `k` (see [`TileSource::variable_count`]), NaN = nodata.
    ///
    /// # Errors
    /// When reading fails; by default, always (a source without variables).
    fn read_variable_window(
        &mut self,
        k: usize,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        let _ = (x0, y0, width, height);
        Err(format!("this source has no variable {k}").into())
    }
}

/// A grid in memory, cut into tiles like a raster file (for tests, and for callers who
/// want tiles of a grid they already hold). A grid with variables
/// (`Grid::with_variables`) gives them as the source's variables.
#[derive(Debug, Clone, Copy)]
pub struct GridSource<'a> {
    grid: &'a Grid,
    max_abs_value: f64,
    integral_heights: bool,
}

impl<'a> GridSource<'a> {
    /// Tiles of `grid`.
    pub fn new(grid: &'a Grid) -> GridSource<'a> {
        let max_abs_value = grid
            .values()
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0, |m: f64, v| m.max(v.abs()));
        let integral_heights = grid
            .values()
            .iter()
            .filter(|v| v.is_finite())
            .all(|v| v.fract() == 0.0);
        GridSource {
            grid,
            max_abs_value,
            integral_heights,
        }
    }
}

impl<'a> TileSource for GridSource<'a> {
    type Reader = GridSource<'a>;

    fn width(&self) -> u32 {
        self.grid.width()
    }

    fn height(&self) -> u32 {
        self.grid.height()
    }

    fn max_abs_value(&self) -> f64 {
        self.max_abs_value
    }

    fn integral_heights(&self) -> bool {
        self.integral_heights
    }

    fn variable_count(&self) -> usize {
        self.grid.variable_count()
    }

    fn variable_max_abs_value(&self, k: usize) -> f64 {
        self.grid
            .variable(k)
            .0
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0, |m: f64, v| m.max(v.abs()))
    }

    fn reader(&self) -> std::result::Result<GridSource<'a>, ReadError> {
        Ok(*self)
    }
}

impl WindowRead for GridSource<'_> {
    fn read_window(
        &mut self,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        cut_window(self.grid, self.grid.values(), (x0, y0, width, height))
    }

    fn read_variable_window(
        &mut self,
        k: usize,
        x0: u32,
        y0: u32,
        width: u32,
        height: u32,
    ) -> std::result::Result<Samples, ReadError> {
        if k >= self.grid.variable_count() {
            return Err(format!("the grid has no variable {k}").into());
        }
        cut_window(self.grid, self.grid.variable(k).0, (x0, y0, width, height))
    }
}

/// The window `(x0, y0, width, height)` of `values`, samples on `grid`'s raster.
fn cut_window(
    grid: &Grid,
    values: &[f64],
    (x0, y0, width, height): (u32, u32, u32, u32),
) -> std::result::Result<Samples, ReadError> {
    let w = grid.width();
    if x0 + width > w || y0 + height > grid.height() {
        return Err(format!("window {width}x{height} at ({x0}, {y0}) is outside the grid").into());
    }
    let values = (y0..y0 + height)
        .flat_map(|y| {
            let row = (y * w + x0) as usize;
            values[row..row + width as usize].iter().copied()
        })
        .collect();
    Ok(Samples::new(width, height, values)?)
}
