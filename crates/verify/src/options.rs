//! What the caller expects of the mesh: triangle orientation and the error bound.

use std::fmt;

use serde::Serialize;

/// The winding every triangle must have, in grid coordinates (x = column, y = row).
///
/// With `orient(a, b, c) = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)`, computed
/// exactly in integers, a triangle is counter-clockwise when `orient > 0` and clockwise when
/// `orient < 0`. Because rows grow downwards in a raster, "counter-clockwise" here looks
/// clockwise on a north-up map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Orientation {
    /// `orient(a, b, c) > 0` for every triangle `[a, b, c]`.
    #[default]
    CounterClockwise,
    /// `orient(a, b, c) < 0` for every triangle `[a, b, c]`.
    Clockwise,
}

impl Orientation {
    /// Sign of `orient(a, b, c)` (twice the signed area) for a triangle with this
    /// orientation: 1 or -1.
    pub fn sign(self) -> i128 {
        match self {
            Orientation::CounterClockwise => 1,
            Orientation::Clockwise => -1,
        }
    }
}

impl fmt::Display for Orientation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Orientation::CounterClockwise => "counter-clockwise",
            Orientation::Clockwise => "clockwise",
        })
    }
}

/// Options of [`verify`](crate::verify).
///
/// The default expects counter-clockwise triangles and no error bound.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VerifyOptions {
    /// The largest allowed `|sample - interpolation|`; `None` only measures the error.
    pub max_error: Option<f64>,
    /// The winding every triangle must have.
    pub orientation: Orientation,
}

impl VerifyOptions {
    /// Default options: counter-clockwise triangles, no error bound.
    pub fn new() -> Self {
        Self::default()
    }

    /// Requires every domain sample to be within `max_error` of the mesh.
    pub fn with_max_error(mut self, max_error: f64) -> Self {
        self.max_error = Some(max_error);
        self
    }

    /// Requires every triangle to have `orientation`.
    pub fn with_orientation(mut self, orientation: Orientation) -> Self {
        self.orientation = orientation;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_setters() {
        let options = VerifyOptions::new();
        assert_eq!(options.max_error, None);
        assert_eq!(options.orientation, Orientation::CounterClockwise);
        let options = options
            .with_max_error(0.5)
            .with_orientation(Orientation::Clockwise);
        assert_eq!(options.max_error, Some(0.5));
        assert_eq!(options.orientation, Orientation::Clockwise);
    }

    #[test]
    fn signs_and_names() {
        assert_eq!(Orientation::CounterClockwise.sign(), 1);
        assert_eq!(Orientation::Clockwise.sign(), -1);
        assert_eq!(Orientation::Clockwise.to_string(), "clockwise");
        assert_eq!(
            Orientation::CounterClockwise.to_string(),
            "counter-clockwise"
        );
    }
}
