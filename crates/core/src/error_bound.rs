//! The paper's per-triangle error bounds (§3.3).

/// Upper bounds on the error of the samples removed inside a triangle (paper §3.3).
///
/// `above` bounds `sample - surface` and `below` bounds `surface - sample` over every
/// original sample in the triangle (closed), so |sample - surface| <= max(above, below).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorBound {
    /// Bound on how far samples lie above the triangle's plane.
    pub above: f64,
    /// Bound on how far samples lie below the triangle's plane.
    pub below: f64,
}

impl ErrorBound {
    /// The larger of the two bounds: a bound on |sample - surface|.
    pub fn max(&self) -> f64 {
        self.above.max(self.below)
    }
}
