//! The error type of the decimation core.

/// What can go wrong in the core; each variant says what the caller should fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The grid's dimensions and its value count disagree, a dimension is zero, or the
    /// grid is too large to index with 32-bit vertex handles.
    #[error(transparent)]
    Grid(#[from] tinsmith_georef::SamplesError),
    /// A border sample that [`crate::decimate_with_border`] was told to remove cannot be.
    #[error("border sample ({x}, {y}) cannot be removed: {problem}")]
    BorderSample {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// Why.
        problem: &'static str,
    },
    /// The maximum edge length is below 2 sample spacings (the full grid's diagonals are
    /// longer than 1).
    #[error("maximum edge length must be at least 2 sample spacings, got {0}")]
    InvalidMaxEdgeLength(u32),
    /// An [`crate::EdgeMetric`] that does not fit the grid (the message says why).
    #[error("edge metric: {0}")]
    EdgeMetric(String),
    /// Some |height| exceeds [`crate::MAX_ABS_HEIGHT`]: errors between such heights could
    /// not be stored or measured.
    #[error(
        "heights reach {0:e} in magnitude; decimation takes heights within ±1e37 (errors are kept as float32)"
    )]
    HeightsTooLarge(f64),
    /// Scattered points or their triangulation are unusable (see [`crate::Scatter::new`],
    /// [`crate::decimate_scatter`]); the message says which and why.
    #[error("{0}")]
    Scatter(String),
    /// A variable's grid is not the height's size ([`crate::Grid::with_variables`]).
    #[error(
        "variable {index} is a {width}x{height} grid; the height's is {expected_width}x{expected_height}"
    )]
    VariableSize {
        /// The variable's index among the variables (0-based).
        index: usize,
        /// Its columns.
        width: u32,
        /// Its rows.
        height: u32,
        /// The height's columns.
        expected_width: u32,
        /// The height's rows.
        expected_height: u32,
    },
    /// Extra variables were given with options they do not support: the error model of
    /// bounds, or a triangle or vertex count target.
    #[error("decimation with several variables {0}")]
    VariablesUnsupported(&'static str),
    /// The maximum error is negative, NaN or infinite.
    #[error("maximum error must be a finite number >= 0, got {0}")]
    InvalidMaxError(f64),
}

/// Result of the core's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;
