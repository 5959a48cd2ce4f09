//! Format-specific choices for writing a mesh: the float32 origin, the STL base, glTF
//! normals.

use crate::origin::LocalOrigin;

/// How [`crate::write_mesh_with`] writes a mesh; each option applies to some formats and
/// is ignored by the others. [`WriteOptions::default`] is what [`crate::write_mesh`] uses.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WriteOptions {
    origin: Option<LocalOrigin>,
    base: Option<f64>,
    normals: bool,
}

impl WriteOptions {
    /// The defaults: origin from the vertices' bounding box, no STL base, no normals.
    pub fn new() -> WriteOptions {
        WriteOptions::default()
    }

    /// STL, glTF: store positions relative to `origin` (default:
    /// [`LocalOrigin::of_points`] of the vertices). Pass the origin used to predict the
    /// written coordinates with [`LocalOrigin::quantize`].
    pub fn with_origin(mut self, origin: impl Into<Option<LocalOrigin>>) -> WriteOptions {
        self.origin = origin.into();
        self
    }

    /// STL: close the surface into a watertight solid: a vertical wall down to `z = base`
    /// under every boundary edge (an edge of exactly one triangle: outer outline and
    /// holes) and a bottom at `base` that mirrors the top triangles with reversed
    /// orientation. `base` must lie below every vertex, also after float32 rounding.
    pub fn with_base(mut self, base: impl Into<Option<f64>>) -> WriteOptions {
        self.base = base.into();
        self
    }

    /// glTF: write a `NORMAL` attribute: per vertex, the area-weighted mean of the normals
    /// of its triangles.
    pub fn with_normals(mut self, normals: bool) -> WriteOptions {
        self.normals = normals;
        self
    }

    /// The origin set with [`WriteOptions::with_origin`].
    pub fn origin(&self) -> Option<LocalOrigin> {
        self.origin
    }

    /// The STL base set with [`WriteOptions::with_base`].
    pub fn base(&self) -> Option<f64> {
        self.base
    }

    /// Whether glTF normals are written.
    pub fn normals(&self) -> bool {
        self.normals
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setters_set_and_defaults_are_off() {
        let options = WriteOptions::new();
        assert_eq!(
            (options.origin(), options.base(), options.normals()),
            (None, None, false)
        );
        let origin = LocalOrigin::new([1.0, 2.0, 3.0]);
        let options = options
            .with_origin(origin)
            .with_base(-5.0)
            .with_normals(true);
        assert_eq!(
            (options.origin(), options.base(), options.normals()),
            (Some(origin), Some(-5.0), true)
        );
    }
}
