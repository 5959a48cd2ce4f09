//! A rectangular grid of scalar samples; NaN marks a sample outside the domain.

use std::sync::Arc;

use tinsmith_georef::Samples;

use crate::variables::{joined, Measured};
use crate::{Result, Variable};

/// A `width` x `height` grid of samples in row-major order (row 0 first).
///
/// Sample `(x, y)` (column, row) sits at integer position `(x, y)`. A sample is *valid* when
/// it is finite; NaN and infinities mark nodata. A *cell* is the unit square with corners
/// `(x, y)`..`(x + 1, y + 1)`; it belongs to the domain when its four corners are valid.
///
/// A grid is [`Samples`] plus what the decimator precomputes from them (the largest
/// |value|, whether heights are integers, runs of equal samples, flat blocks).
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Shared, so that a grid with raised heights is no copy of the samples.
    samples: Arc<Samples>,
    /// Largest absolute valid value (0 without valid samples).
    max_abs: f64,
    /// See [`Grid::integral_heights`].
    integral_heights: bool,
    /// See [`Grid::equal_runs`].
    equal_runs: Option<Arc<Vec<u16>>>,
    /// See [`Grid::flat_value`]; built with `equal_runs`.
    flat_blocks: Arc<Vec<FlatLevel>>,
    /// See [`Grid::vertex_height`]; 0 when vertices sit at their samples' values.
    raise: f64,
    /// Extra variables ([`Grid::with_variables`]); empty for a grid of heights alone (a
    /// slice, so that the exact model's test for none reads no memory beyond the grid).
    variables: Arc<[Measured]>,
}

/// Square blocks of one size, each with its samples' common value when they are all bit
/// for bit equal and finite ([`NOT_FLAT`] otherwise).
#[derive(Debug, Clone, PartialEq)]
struct FlatLevel {
    /// Blocks are `1 << shift` samples a side.
    shift: u32,
    columns: usize,
    bits: Vec<u64>,
}

/// A block whose samples differ (or hold nodata): the bits of a NaN, which no flat block
/// holds.
const NOT_FLAT: u64 = u64::MAX;

/// The smallest flat blocks are this many samples a side (as a shift).
const FLAT_BLOCK_SHIFT: u32 = 4;

/// Runs of equal samples this long or longer are measured at their two ends only.
pub(crate) const MIN_EQUAL_RUN: u16 = 8;

/// `width x height x max|value|` below this keeps an integer grid's plane arithmetic exact
/// in `f64` (see [`Grid::integral_heights`]).
const INTEGRAL_PRODUCT_LIMIT: f64 = (1u64 << 50) as f64;

impl Grid {
    /// Wraps row-major `values`; fails if `values.len() != width * height`, if either
    /// dimension is zero, or if the grid has 2^32 - 1 samples or more ([`crate::Error::Grid`]).
    pub fn new(width: u32, height: u32, values: Vec<f64>) -> Result<Grid> {
        Ok(Grid::from_samples(Samples::new(width, height, values)?))
    }

    /// The grid of `samples` (which [`Samples::new`] has already checked), with the
    /// decimator's precomputed data built from them; the samples are kept, not copied.
    pub fn from_samples(samples: Samples) -> Grid {
        let (width, height, values) = (samples.width(), samples.height(), samples.values());
        let (max_abs, integers) = values
            .iter()
            .filter(|v| v.is_finite())
            .fold((0.0f64, true), |(m, integers), v| {
                (m.max(v.abs()), integers && v.fract() == 0.0)
            });
        let integral_heights = integers && Grid::integral_product_fits(width, height, max_abs);
        let equal_runs = equal_runs(width as usize, values);
        let flat_blocks = match &equal_runs {
            Some(runs) => flat_levels(width as usize, height as usize, values, runs),
            None => Vec::new(),
        };
        Grid {
            samples: Arc::new(samples),
            max_abs,
            integral_heights,
            equal_runs: equal_runs.map(Arc::new),
            flat_blocks: Arc::new(flat_blocks),
            raise: 0.0,
            variables: Arc::from(Vec::new()),
        }
    }

    /// The grid of `height` carrying `variables` (paper §6): decimation then removes a
    /// vertex only when every triangle it makes keeps the height within
    /// [`crate::DecimationOptions::max_error`] and each variable within its own bound, at
    /// every sample of the domain (exact error model only). The domain is where the
    /// height and every variable are valid: a sample nodata in any of them is nodata in
    /// the grid. Vertices carry every variable at its sample's value (never raised).
    ///
    /// # Errors
    /// [`crate::Error::VariableSize`] when a variable's grid is not the height's size;
    /// [`crate::Error::HeightsTooLarge`] when a variable's |value| exceeds
    /// [`crate::MAX_ABS_HEIGHT`].
    pub fn with_variables(height: Samples, variables: Vec<Variable>) -> Result<Grid> {
        let (height, measured) = joined(height, variables)?;
        Ok(Grid {
            variables: Arc::from(measured),
            ..Grid::from_samples(height)
        })
    }

    /// Number of extra variables ([`Grid::with_variables`]; 0 for heights alone).
    pub fn variable_count(&self) -> usize {
        self.variables.len()
    }

    /// Variable `k`'s samples (row-major) and bound.
    ///
    /// # Panics
    /// When `k >= self.variable_count()`.
    pub fn variable(&self, k: usize) -> (&[f64], f64) {
        let v = &self.variables[k];
        (v.grid.values(), v.max_error)
    }

    /// The variables as the decimator measures them.
    pub(crate) fn variables(&self) -> &[Measured] {
        &self.variables
    }

    /// The heights alone, without the variables (the samples are shared, not copied).
    pub(crate) fn heights_alone(&self) -> Grid {
        Grid {
            variables: Arc::from([]),
            ..self.clone()
        }
    }

    /// The grid whose variables are scaled for a run enforcing `height_limit` on heights
    /// (see `crate::variables`); the samples are shared, not copied.
    pub(crate) fn with_height_limit(&self, height_limit: f64) -> Grid {
        Grid {
            variables: self
                .variables
                .iter()
                .map(|v| v.for_limit(height_limit))
                .collect(),
            ..self.clone()
        }
    }

    /// The grid with its vertices `raise` above their samples ([`Grid::vertex_height`]),
    /// except on the grid's outer rows and columns (so tiles sharing a border agree on its
    /// heights without reading each other); it shares the samples, not copies them, and
    /// does not claim [`Grid::integral_heights`].
    pub(crate) fn with_raised_heights(&self, raise: f64) -> Grid {
        Grid {
            integral_heights: false,
            raise,
            ..self.clone()
        }
    }

    /// The height of a TIN vertex at sample `i` (row-major): the sample's value, or that
    /// raised on a grid [`Grid::with_raised_heights`] made.
    pub(crate) fn vertex_height(&self, i: usize) -> f64 {
        let w = self.width() as usize;
        self.vertex_height_at(i, i % w, i / w)
    }

    /// [`Grid::vertex_height`] of sample `i`, which is at column `x`, row `y`.
    #[inline]
    pub(crate) fn vertex_height_at(&self, i: usize, x: usize, y: usize) -> f64 {
        let (width, height) = (self.width() as usize, self.height() as usize);
        let inner = x > 0 && y > 0 && x + 1 < width && y + 1 < height;
        if self.raise != 0.0 && inner {
            self.values()[i] + self.raise
        } else {
            self.values()[i]
        }
    }

    /// Whether some vertex heights may differ from their samples' values.
    pub(crate) fn has_vertex_heights(&self) -> bool {
        self.raise != 0.0
    }

    /// For each sample, how many samples from it rightwards in its row are bit for bit
    /// equal to it (at least 1, capped at `u16::MAX`); `None` when long runs (at least
    /// [`MIN_EQUAL_RUN`]) cover under an eighth of the grid, as on most terrain. Flat
    /// ground (water, filled voids, the air around a CT slice) is where they pay: along
    /// a run the error against a plane is monotone, so only its two ends need measuring.
    pub(crate) fn equal_runs(&self) -> Option<&[u16]> {
        self.equal_runs.as_deref().map(Vec::as_slice)
    }

    /// `Some(v)` when every sample of columns `x0..=x1`, rows `y0..=y1` (inside the grid)
    /// is known to equal `v` bit for bit, from at most four aligned blocks covering them;
    /// `None` when they differ or that is not known (a grid without [`Grid::equal_runs`],
    /// or a rectangle straddling blocks that are not all flat).
    pub(crate) fn flat_value(&self, x0: i64, x1: i64, y0: i64, y1: i64) -> Option<f64> {
        let level = self.flat_blocks.iter().find(|l| {
            (x1 >> l.shift) - (x0 >> l.shift) <= 1 && (y1 >> l.shift) - (y0 >> l.shift) <= 1
        })?;
        let at = |bx: i64, by: i64| level.bits[by as usize * level.columns + bx as usize];
        let bits = at(x0 >> level.shift, y0 >> level.shift);
        let same = [
            (x1 >> level.shift, y0 >> level.shift),
            (x0 >> level.shift, y1 >> level.shift),
            (x1 >> level.shift, y1 >> level.shift),
        ]
        .iter()
        .all(|&(bx, by)| at(bx, by) == bits);
        (bits != NOT_FLAT && same).then(|| f64::from_bits(bits))
    }

    /// Whether a grid of `width x height` integer samples up to `max_abs` in magnitude is
    /// small enough for [`Grid::integral_heights`]: `width x height x max(max_abs, 1)` is
    /// below 2^50. (Tiles of one raster use it to decide the same for all of them.)
    pub fn integral_product_fits(width: u32, height: u32, max_abs: f64) -> bool {
        f64::from(width) * f64::from(height) * max_abs.max(1.0) < INTEGRAL_PRODUCT_LIMIT
    }

    /// Whether every valid sample is an integer and `width x height x max|value|` is below
    /// 2^50. Then whether a sample lies on the plane through three others is decided
    /// exactly by an integer determinant, and a verifier interpolating such a plane in
    /// `f64` with integer barycentric weights gets the sample exactly: an error of exactly
    /// 0 can be promised and checked (integer DEMs at `max_error` 0).
    pub fn integral_heights(&self) -> bool {
        self.integral_heights
    }

    /// Number of columns.
    pub fn width(&self) -> u32 {
        self.samples.width()
    }

    /// Number of rows.
    pub fn height(&self) -> u32 {
        self.samples.height()
    }

    /// All samples, row-major; nodata samples are non-finite.
    pub fn values(&self) -> &[f64] {
        self.samples.values()
    }

    /// The value at column `x`, row `y`, or `None` when it is nodata or out of range.
    pub fn get(&self, x: u32, y: u32) -> Option<f64> {
        self.samples.get(x, y)
    }

    /// Number of valid (finite) samples.
    pub fn valid_count(&self) -> usize {
        self.samples.valid_count()
    }

    /// Number of cells whose four corners are valid: the domain's area in cell units.
    pub fn valid_cell_count(&self) -> usize {
        self.samples.valid_cell_count()
    }

    /// Number of samples that are a corner of at least one valid cell: the vertices of
    /// the full mesh.
    pub fn domain_sample_count(&self) -> usize {
        let (w, h) = (self.width() as usize, self.height() as usize);
        if self.samples.all_valid() {
            return if w > 1 && h > 1 { w * h } else { 0 };
        }
        let cell = |x: usize, y: usize| x < w - 1 && y < h - 1 && self.cell_is_valid(x, y);
        let mut n = 0;
        for y in 0..h {
            for x in 0..w {
                let around = cell(x, y)
                    || (x > 0 && cell(x - 1, y))
                    || (y > 0 && cell(x, y - 1))
                    || (x > 0 && y > 0 && cell(x - 1, y - 1));
                n += usize::from(around);
            }
        }
        n
    }

    pub(crate) fn cell_is_valid(&self, x: usize, y: usize) -> bool {
        self.samples.cell_is_valid(x, y)
    }

    /// Largest absolute valid value (0 for a grid without valid samples): what
    /// [`crate::effective_limit`] takes as `max_abs_value` for this grid.
    pub fn max_abs_value(&self) -> f64 {
        self.max_abs
    }
}

/// [`Grid::flat_value`]'s blocks, from 16 samples a side up to one block covering the grid.
fn flat_levels(width: usize, height: usize, values: &[f64], runs: &[u16]) -> Vec<FlatLevel> {
    let side = 1usize << FLAT_BLOCK_SHIFT;
    let (columns, rows) = (width.div_ceil(side), height.div_ceil(side));
    let mut bits = vec![NOT_FLAT; columns * rows];
    for by in 0..rows {
        for bx in 0..columns {
            let (x0, y0) = (bx * side, by * side);
            let w = side.min(width - x0);
            let first = values[y0 * width + x0];
            let flat = first.is_finite()
                && (y0..(y0 + side).min(height)).all(|y| {
                    let i = y * width + x0;
                    values[i].to_bits() == first.to_bits() && usize::from(runs[i]) >= w
                });
            if flat {
                bits[by * columns + bx] = first.to_bits();
            }
        }
    }
    let mut levels = vec![FlatLevel {
        shift: FLAT_BLOCK_SHIFT,
        columns,
        bits,
    }];
    loop {
        let below = levels.last().expect("one level");
        let rows = below.bits.len() / below.columns;
        if below.columns == 1 && rows == 1 {
            return levels;
        }
        let (columns, up_rows) = (below.columns.div_ceil(2), rows.div_ceil(2));
        let mut bits = vec![NOT_FLAT; columns * up_rows];
        for by in 0..up_rows {
            for bx in 0..columns {
                let first = below.bits[2 * by * below.columns + 2 * bx];
                let children = (2 * by..(2 * by + 2).min(rows))
                    .flat_map(|y| (2 * bx..(2 * bx + 2).min(below.columns)).map(move |x| (x, y)));
                if children
                    .into_iter()
                    .all(|(x, y)| below.bits[y * below.columns + x] == first)
                {
                    bits[by * columns + bx] = first;
                }
            }
        }
        let shift = below.shift + 1;
        levels.push(FlatLevel {
            shift,
            columns,
            bits,
        });
    }
}

/// [`Grid::equal_runs`] of row-major `values` with `width` columns.
fn equal_runs(width: usize, values: &[f64]) -> Option<Vec<u16>> {
    let mut runs = vec![1u16; values.len()];
    let mut long = 0usize;
    for (row, runs) in values.chunks_exact(width).zip(runs.chunks_exact_mut(width)) {
        for x in (0..width - 1).rev() {
            if row[x].to_bits() == row[x + 1].to_bits() {
                runs[x] = runs[x + 1].saturating_add(1);
                long += usize::from(runs[x] >= MIN_EQUAL_RUN);
            }
        }
    }
    (long >= values.len() / 8).then_some(runs)
}
