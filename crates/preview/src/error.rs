//! What can go wrong when drawing a picture.

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PreviewError {
    /// The size asked for cannot be drawn.
    #[error("the picture's size must be 16 to {max} pixels, got {size}")]
    Size {
        /// The size asked for.
        size: u32,
        /// The largest size drawn.
        max: u32,
    },
    /// The slices do not describe one raster and one mesh on it.
    #[error("{0}")]
    Scene(String),
}
