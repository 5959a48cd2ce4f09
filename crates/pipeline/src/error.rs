//! Why a run failed: one error type whose message, with its causes, names the file and
//! the problem.

use std::fmt::Display;

/// Why a pipeline run failed. Its `Display` and its chain of [`std::error::Error::source`]s
/// together say which file and what went wrong; [`Error::chain_text`] joins them as the
/// CLI prints them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The input, the job or an output path cannot give what was asked; the message
    /// names the file and the problem, and nothing was written.
    #[error("{0}")]
    Refused(String),
    /// A step on a file failed: `context` names the file and the step, the source why.
    #[error("{context}")]
    Context {
        /// The file and the step.
        context: String,
        /// Why it failed.
        #[source]
        source: Box<Error>,
    },
    /// Reading a raster failed.
    #[error(transparent)]
    Raster(#[from] tinsmith_raster::Error),
    /// Reading or writing a mesh or lines file failed.
    #[error(transparent)]
    Formats(#[from] tinsmith_formats::Error),
    /// Checking, staging or placing an output failed.
    #[error(transparent)]
    Output(#[from] tinsmith_output::Error),
    /// Decimation refused its input or options.
    #[error(transparent)]
    Core(#[from] tinsmith_core::Error),
    /// Contouring refused its input or levels.
    #[error(transparent)]
    Contour(#[from] tinsmith_contour::Error),
    /// The verifier could not measure a mesh (inconsistent input, not a failed bound).
    #[error(transparent)]
    Verify(#[from] tinsmith_verify::VerifyError),
    /// The tiled engine failed.
    #[error(transparent)]
    Tiling(#[from] tinsmith_tiling::Error),
    /// Building the terrain pyramid failed.
    #[error(transparent)]
    Terrain(#[from] tinsmith_terrain::TerrainError),
    /// A pyramid's destination failed.
    #[error(transparent)]
    Store(#[from] tinsmith_store::StoreError),
    /// A file position is not on a sample of the raster.
    #[error(transparent)]
    Position(#[from] tinsmith_georef::PositionError),
    /// A picture could not be drawn.
    #[error(transparent)]
    Preview(#[from] tinsmith_preview::PreviewError),
    /// A point file could not be read.
    #[error(transparent)]
    Points(#[from] tinsmith_points::Error),
    /// An I/O operation failed (the `io::Error` is also the source, so that a closed
    /// pipe can be told apart).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A report could not be serialized.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// The results of every run.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// The message and its causes on one line, joined by ": " (a cause that only repeats
    /// the message before it is left out).
    pub fn chain_text(&self) -> String {
        let mut last = self.to_string();
        let mut text = last.clone();
        let mut cause = std::error::Error::source(self);
        while let Some(e) = cause {
            let shown = e.to_string();
            if shown != last {
                text.push_str(": ");
                text.push_str(&shown);
            }
            last = shown;
            cause = e.source();
        }
        text
    }

    /// This error with `context` (the file and the step) in front.
    pub(crate) fn context(self, context: impl Display) -> Error {
        Error::Context {
            context: context.to_string(),
            source: Box::new(self),
        }
    }
}

/// `anyhow`-style context on results whose error converts into [`Error`].
pub(crate) trait Context<T> {
    /// The result, its error with the context `f` gives in front.
    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T>;
}

impl<T, E: Into<Error>> Context<T> for std::result::Result<T, E> {
    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T> {
        self.map_err(|e| e.into().context(f()))
    }
}

/// Returns a [`Error::Refused`] with the formatted message.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err($crate::Error::Refused(format!($($arg)*)))
    };
}
pub(crate) use bail;
