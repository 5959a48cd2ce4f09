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
    /// they parse back to the same `f64`. The CRS goes into a `# crs:` comment and a `.prj`
    /// sidecar.
    Obj,
    /// Binary STL: one float32 facet per triangle, relative to a [`crate::LocalOrigin`]
    /// stored as text in the 80-byte header; optionally closed into a solid (see
    /// [`crate::WriteOptions::with_base`]). The CRS goes into a `.prj` sidecar.
    Stl,
    /// glTF 2.0 binary (`.glb`): float32 positions relative to a [`crate::LocalOrigin`]
    /// held in the node's translation, Y up (see the `glb` section of the crate docs). The
    /// CRS goes into a `.prj` sidecar and the node's `extras`.
    Glb,
    /// GeoJSON (RFC 7946): a `FeatureCollection` of one `Polygon` Z feature per triangle.
    /// Coordinates are written as given; a mesh whose EPSG code is 4326 is written as plain
    /// RFC 7946 (longitude, latitude), any other with a `crs` member and a note.
    GeoJson,
    /// FlatGeobuf: one `Triangle` Z feature per triangle with an `id` column (the triangle's
    /// position), the CRS (WKT and EPSG code) in the header, and a spatial index.
    FlatGeobuf,
    /// LandXML 1.2 (`.xml`): one `Surface` with `Definition surfType="TIN"`, points as
    /// `northing easting elevation`, 1-based faces, `Units`, `CoordinateSystem` and
    /// `Application`.
    LandXml,
}

impl MeshFormat {
    /// Every supported format, in the order they are listed in messages.
    pub const ALL: [MeshFormat; 7] = [
        MeshFormat::Ply,
        MeshFormat::Obj,
        MeshFormat::Stl,
        MeshFormat::Glb,
        MeshFormat::GeoJson,
        MeshFormat::FlatGeobuf,
        MeshFormat::LandXml,
    ];

    /// Picks the format from the path's extension, ignoring ASCII case (`tile.PLY` is PLY);
    /// the format's [`MeshFormat::name`] works too (`tin.landxml` is LandXML).
    ///
    /// # Errors
    /// [`Error::UnknownExtension`], naming the path and the supported extensions, if the
    /// extension is missing, not UTF-8 or not one of [`MeshFormat::extension`] or
    /// [`MeshFormat::name`].
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        path.extension()
            .and_then(|extension| extension.to_str())
            .and_then(|extension| {
                Self::ALL.into_iter().find(|format| {
                    format.extension().eq_ignore_ascii_case(extension)
                        || format.name().eq_ignore_ascii_case(extension)
                })
            })
            .ok_or_else(|| Error::UnknownExtension {
                path: path.to_path_buf(),
            })
    }

    /// Picks the format from its name (`"ply"`, `"obj"`, `"stl"`, `"glb"`, `"geojson"`,
    /// `"fgb"`, `"landxml"`), ignoring ASCII case and surrounding whitespace.
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

    /// The lower-case name, as accepted by [`MeshFormat::from_name`].
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
            MeshFormat::Stl => "stl",
            MeshFormat::Glb => "glb",
            MeshFormat::GeoJson => "geojson",
            MeshFormat::FlatGeobuf => "fgb",
            MeshFormat::LandXml => "landxml",
        }
    }

    /// The file extension without the dot, as recognised by [`MeshFormat::from_path`]: the
    /// name, except `xml` for LandXML.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::LandXml => "xml",
            other => other.name(),
        }
    }

    /// Whether the format carries per-vertex variables ([`crate::MeshRef::attributes`]):
    /// PLY and glTF per vertex, GeoJSON and FlatGeobuf per triangle (corner means).
    pub fn carries_attributes(self) -> bool {
        matches!(
            self,
            MeshFormat::Ply | MeshFormat::Glb | MeshFormat::GeoJson | MeshFormat::FlatGeobuf
        )
    }

    /// Whether the format stores coordinates as float32 relative to a
    /// [`crate::LocalOrigin`] (STL, glTF): what it gives back is
    /// [`crate::LocalOrigin::quantize`] of what was written.
    pub fn is_float32(self) -> bool {
        matches!(self, MeshFormat::Stl | MeshFormat::Glb)
    }

    /// Whether the format cannot hold a full CRS, so that [`crate::write_mesh`] writes
    /// the WKT into a `.prj` sidecar (OBJ, STL, glTF).
    pub fn uses_prj_sidecar(self) -> bool {
        matches!(self, MeshFormat::Obj | MeshFormat::Stl | MeshFormat::Glb)
    }

    /// `".ply, .obj, ..."`, for messages.
    pub(crate) fn supported_extensions() -> String {
        let mut list: Vec<String> = Self::ALL
            .iter()
            .map(|format| format!(".{}", format.extension()))
            .collect();
        // Names that differ from their extension work as extensions too (`from_path`).
        list.extend(
            Self::ALL
                .iter()
                .filter(|format| format.name() != format.extension())
                .map(|format| format!(".{}", format.name())),
        );
        list.join(", ")
    }

    /// `"ply, obj, ..."`, for messages.
    pub(crate) fn supported_names() -> String {
        let list: Vec<&str> = Self::ALL.iter().map(|format| format.name()).collect();
        list.join(", ")
    }
}

/// Display name: `PLY`, `OBJ`, `STL`, `glTF`, `GeoJSON`, `FlatGeobuf`, `LandXML`.
impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Ply => "PLY",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Stl => "STL",
            MeshFormat::Glb => "glTF",
            MeshFormat::GeoJson => "GeoJSON",
            MeshFormat::FlatGeobuf => "FlatGeobuf",
            MeshFormat::LandXml => "LandXML",
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
            ("t.STL", MeshFormat::Stl),
            ("t.glb", MeshFormat::Glb),
            ("t.GeoJSON", MeshFormat::GeoJson),
            ("t.fgb", MeshFormat::FlatGeobuf),
            ("t.xml", MeshFormat::LandXml),
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
        assert!(
            message.contains(".ply, .obj, .stl, .glb, .geojson, .fgb, .xml, .landxml"),
            "{message}"
        );
    }

    #[test]
    fn from_name_and_from_str() {
        assert_eq!(MeshFormat::from_name("PLY").ok(), Some(MeshFormat::Ply));
        assert_eq!(" obj ".parse::<MeshFormat>().ok(), Some(MeshFormat::Obj));
        assert_eq!(
            MeshFormat::from_name("LandXML").ok(),
            Some(MeshFormat::LandXml)
        );
        let error = MeshFormat::from_name("dxf").err().map(|e| e.to_string());
        assert_eq!(
            error.as_deref(),
            Some(
                "unknown mesh format `dxf` (supported: ply, obj, stl, glb, geojson, fgb, landxml)"
            )
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
        // The format's name works as an extension too.
        assert_eq!(
            MeshFormat::from_path(Path::new("tin.LandXML")).ok(),
            Some(MeshFormat::LandXml)
        );
    }
}
