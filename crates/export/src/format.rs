//! The mesh file formats and how they are recognised from paths and names.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::error::{Error, Result};

/// A mesh file format this crate writes and reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MeshFormat {
    /// Stanford PLY. Written as `binary_little_endian 1.0` with `double` coordinates and
    /// `int` vertex indices; read as ASCII or binary of either byte order.
    Ply,
    /// Wavefront OBJ: `v x y z` and 1-based `f a b c` lines, coordinates written so that
    /// they parse back to the same `f64`.
    Obj,
}

impl MeshFormat {
    /// Every supported format, in the order they are listed in messages.
    pub const ALL: [MeshFormat; 2] = [MeshFormat::Ply, MeshFormat::Obj];

    /// Picks the format from the path's extension, ignoring ASCII case (`tile.PLY` is PLY).
    ///
    /// # Errors
    /// [`Error::UnknownExtension`], naming the path and the supported extensions, if the
    /// extension is missing, not UTF-8 or not one of [`MeshFormat::extension`].
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        path.extension()
            .and_then(|extension| extension.to_str())
            .and_then(|extension| {
                Self::ALL
                    .into_iter()
                    .find(|format| format.extension().eq_ignore_ascii_case(extension))
            })
            .ok_or_else(|| Error::UnknownExtension {
                path: path.to_path_buf(),
            })
    }

    /// Picks the format from its name (`"ply"`, `"obj"`), ignoring ASCII case and
    /// surrounding whitespace.
    ///
    /// # Errors
    /// [`Error::UnknownFormatName`] if the name is not one of [`MeshFormat::name`].
    pub fn from_name(name: &str) -> Result<MeshFormat> {
        let trimmed = name.trim();
        Self::ALL
            .into_iter()
            .find(|format| format.name().eq_ignore_ascii_case(trimmed))
            .ok_or_else(|| Error::UnknownFormatName {
                name: name.to_owned(),
            })
    }

    /// The lower-case name, as accepted by [`MeshFormat::from_name`]: `"ply"` or `"obj"`.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
        }
    }

    /// The file extension without the dot, as recognised by [`MeshFormat::from_path`].
    pub fn extension(self) -> &'static str {
        self.name()
    }

    /// `".ply, .obj"`, for messages.
    pub(crate) fn supported_extensions() -> String {
        let list: Vec<String> = Self::ALL
            .iter()
            .map(|format| format!(".{}", format.extension()))
            .collect();
        list.join(", ")
    }

    /// `"ply, obj"`, for messages.
    pub(crate) fn supported_names() -> String {
        let list: Vec<&str> = Self::ALL.iter().map(|format| format.name()).collect();
        list.join(", ")
    }
}

/// Upper-case display name: `PLY`, `OBJ`.
impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Ply => "PLY",
            MeshFormat::Obj => "OBJ",
        })
    }
}

/// Same as [`MeshFormat::from_name`].
impl FromStr for MeshFormat {
    type Err = Error;

    fn from_str(name: &str) -> Result<MeshFormat> {
        MeshFormat::from_name(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_path_ignores_case() {
        for (path, format) in [
            ("a.ply", MeshFormat::Ply),
            ("dir.d/b.PLY", MeshFormat::Ply),
            ("c.Obj", MeshFormat::Obj),
            ("/abs/tile.0.obj", MeshFormat::Obj),
        ] {
            assert_eq!(
                MeshFormat::from_path(Path::new(path)).ok(),
                Some(format),
                "{path}"
            );
        }
    }

    #[test]
    fn from_path_rejects_unknown_and_missing_extensions() {
        for path in ["tin.xyz", "tin", "tin.ply.gz", ".ply", ""] {
            match MeshFormat::from_path(Path::new(path)) {
                Err(Error::UnknownExtension { path: reported }) => {
                    assert_eq!(reported, Path::new(path));
                }
                other => panic!("{path}: {other:?}"),
            }
        }
        let message = MeshFormat::from_path(Path::new("out/tin.xyz"))
            .err()
            .map(|error| error.to_string())
            .unwrap_or_default();
        assert!(message.contains("out/tin.xyz"), "{message}");
        assert!(message.contains(".ply, .obj"), "{message}");
    }

    #[test]
    fn from_name_and_from_str() {
        assert_eq!(MeshFormat::from_name("PLY").ok(), Some(MeshFormat::Ply));
        assert_eq!(" obj ".parse::<MeshFormat>().ok(), Some(MeshFormat::Obj));
        let error = MeshFormat::from_name("stl").err().map(|e| e.to_string());
        assert_eq!(
            error.as_deref(),
            Some("unknown mesh format `stl` (supported: ply, obj)")
        );
    }

    #[test]
    fn names_round_trip() {
        for format in MeshFormat::ALL {
            assert_eq!(MeshFormat::from_name(format.name()).ok(), Some(format));
            let path = format!("x.{}", format.extension());
            assert_eq!(MeshFormat::from_path(Path::new(&path)).ok(), Some(format));
        }
        assert_eq!(MeshFormat::Ply.to_string(), "PLY");
    }
}
