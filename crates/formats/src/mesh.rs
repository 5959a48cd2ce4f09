//! The mesh as handed to the writers (borrowed) and returned by the readers (owned).

use std::path::Path;

use crate::error::{Error, Result};
use crate::format::MeshFormat;

/// A borrowed triangle mesh to write: world coordinates, triangles and an optional CRS.
///
/// Triangles are written in the order and orientation given. [`crate::write_mesh`] checks
/// before creating any file that every coordinate is finite and every index is below
/// `vertices.len()`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MeshRef<'a> {
    /// Vertex positions: world x, y, z.
    pub vertices: &'a [[f64; 3]],
    /// Triangles as 0-based indices into `vertices`.
    pub triangles: &'a [[u32; 3]],
    /// The coordinate reference system as WKT, recorded in the file (or its `.prj`
    /// sidecar, see [`crate::MeshFormat::uses_prj_sidecar`]) if given.
    pub crs_wkt: Option<&'a str>,
    /// The CRS's EPSG code, when known: recorded by the formats that hold one (FlatGeobuf,
    /// LandXML, GeoJSON). `Some(4326)` means longitude, latitude in degrees (GeoJSON then
    /// writes plain RFC 7946).
    pub epsg: Option<u32>,
    /// Values carried per vertex besides the position (several variables over one
    /// mesh); written by PLY (a `double` property each), glTF (a float32 `_NAME`
    /// attribute each, the name in capitals), GeoJSON and FlatGeobuf (per triangle: the
    /// mean of its three corners' values, a number property or `Double` column each);
    /// refused by OBJ, STL and LandXML.
    pub attributes: &'a [VertexAttribute<'a>],
    /// An RGB colour per vertex (three 8-bit bands carried as colours): PLY `uchar red
    /// green blue` properties, glTF `COLOR_0` (float, 0..1), OBJ `v x y z r g b` (0..1);
    /// refused by the other formats.
    pub colours: Option<&'a [[u8; 3]]>,
}

/// One value per vertex, under a name (a PLY property name: no whitespace).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexAttribute<'a> {
    /// The name the file gives it.
    pub name: &'a str,
    /// One value per vertex, in vertex order.
    pub values: &'a [f64],
}

/// The mean of `values` at the corners of triangle `t`, as GeoJSON and FlatGeobuf
/// write it: summed in corner order, divided by 3.
pub(crate) fn corner_mean(values: &[f64], t: [u32; 3]) -> f64 {
    (values[t[0] as usize] + values[t[1] as usize] + values[t[2] as usize]) / 3.0
}

impl<'a> MeshRef<'a> {
    /// A mesh without a CRS.
    pub fn new(vertices: &'a [[f64; 3]], triangles: &'a [[u32; 3]]) -> Self {
        MeshRef {
            vertices,
            triangles,
            crs_wkt: None,
            epsg: None,
            attributes: &[],
            colours: None,
        }
    }

    /// Sets the per-vertex colours (see [`MeshRef::colours`]).
    pub fn with_colours(mut self, colours: Option<&'a [[u8; 3]]>) -> Self {
        self.colours = colours;
        self
    }

    /// Sets the per-vertex attributes (see [`MeshRef::attributes`]).
    pub fn with_attributes(mut self, attributes: &'a [VertexAttribute<'a>]) -> Self {
        self.attributes = attributes;
        self
    }

    /// Sets the CRS's EPSG code (see [`MeshRef::epsg`]).
    pub fn with_epsg(mut self, epsg: impl Into<Option<u32>>) -> Self {
        self.epsg = epsg.into();
        self
    }

    /// Sets the CRS as WKT (or any other one-line text such as `EPSG:32633`).
    ///
    /// Files hold the CRS on one header line: line breaks are written as spaces and
    /// surrounding whitespace is dropped, so a WKT without line breaks or surrounding
    /// whitespace reads back unchanged. A CRS that is empty after this is not written.
    pub fn with_crs_wkt(mut self, crs_wkt: impl Into<Option<&'a str>>) -> Self {
        self.crs_wkt = crs_wkt.into();
        self
    }

    /// The CRS as it is written: on one line, trimmed, `None` if empty.
    pub(crate) fn crs_line(&self) -> Option<String> {
        let wkt = self.crs_wkt?;
        let line = wkt.replace("\r\n", " ").replace(['\r', '\n'], " ");
        let line = line.trim();
        (!line.is_empty()).then(|| line.to_owned())
    }

    /// Checks what the readers check, so that no file is written that cannot be read back.
    pub(crate) fn check(&self, path: &Path, format: MeshFormat) -> Result<()> {
        if let Some(attribute) = self.attributes.first() {
            if !format.carries_attributes() {
                return Err(Error::BadOption {
                    path: path.to_path_buf(),
                    reason: format!(
                        "{format} carries heights only; variables (`{}`) are written to \
                         PLY, glTF, GeoJSON or FlatGeobuf",
                        attribute.name
                    ),
                });
            }
        }
        if let Some(colours) = self.colours {
            if !matches!(format, MeshFormat::Ply | MeshFormat::Glb | MeshFormat::Obj)
                || colours.len() != self.vertices.len()
            {
                return Err(Error::BadOption {
                    path: path.to_path_buf(),
                    reason: format!(
                        "vertex colours go to PLY, glTF or OBJ, one per vertex ({} for {} \
                         vertices, {format})",
                        colours.len(),
                        self.vertices.len()
                    ),
                });
            }
        }
        for attribute in self.attributes {
            let bad_name = attribute.name.is_empty()
                || attribute
                    .name
                    .chars()
                    .any(|c| c.is_whitespace() || !c.is_ascii())
                || ["x", "y", "z"].contains(&attribute.name)
                || self
                    .attributes
                    .iter()
                    .filter(|a| a.name == attribute.name)
                    .count()
                    > 1;
            if bad_name || attribute.values.len() != self.vertices.len() {
                return Err(Error::BadOption {
                    path: path.to_path_buf(),
                    reason: format!(
                        "vertex attribute `{}`: {}",
                        attribute.name,
                        if bad_name {
                            "not a distinct PLY property name"
                        } else {
                            "not one value per vertex"
                        }
                    ),
                });
            }
        }
        if format == MeshFormat::Ply {
            // PLY indices are written as `int`.
            let max = i32::MAX as usize + 1;
            if self.vertices.len() > max {
                return Err(Error::TooManyVertices {
                    path: path.to_path_buf(),
                    format,
                    count: self.vertices.len(),
                    max,
                });
            }
        }
        if let Some(vertex) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(Error::NonFiniteVertex {
                path: path.to_path_buf(),
                vertex,
                position: self.vertices[vertex],
            });
        }
        let vertex_count = self.vertices.len();
        for (triangle, corners) in self.triangles.iter().enumerate() {
            if let Some(&index) = corners.iter().find(|&&i| i as usize >= vertex_count) {
                return Err(Error::IndexOutOfRange {
                    path: path.to_path_buf(),
                    triangle,
                    index,
                    vertex_count,
                });
            }
        }
        Ok(())
    }
}

/// A triangle mesh read from a file.
///
/// [`crate::read_mesh`] guarantees that every coordinate is finite and every index is
/// below `vertices.len()`; triangles keep the file's order and orientation.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct Mesh {
    /// Vertex positions: x, y, z.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// The CRS the file records: `comment crs …` in PLY, `# crs: …` in OBJ, the header's
    /// WKT in FlatGeobuf, `ogcWktCode` in LandXML, the `crs_wkt` member in GeoJSON (or the
    /// `crs` member's name when it is not an EPSG code). `.prj` sidecars are not read.
    pub crs_wkt: Option<String>,
    /// The EPSG code the file records (FlatGeobuf, LandXML, GeoJSON). A GeoJSON file
    /// without a `crs` member is RFC 7946 longitude, latitude: `Some(4326)`.
    pub epsg: Option<u32>,
    /// Per-vertex values besides the position, with their names: a PLY file's other
    /// scalar vertex properties, in header order; a glTF file's float `_NAME` attributes
    /// as `NAME`; none from the other formats.
    pub attributes: Vec<(String, Vec<f64>)>,
}

impl Mesh {
    /// A mesh without a CRS.
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh {
            vertices,
            triangles,
            crs_wkt: None,
            epsg: None,
            attributes: Vec::new(),
        }
    }

    /// The values of attribute `name`, one per vertex.
    pub fn attribute(&self, name: &str) -> Option<&[f64]> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// Borrows the mesh for [`crate::write_mesh`] (without its attributes, which
    /// [`MeshRef::with_attributes`] takes as borrowed [`VertexAttribute`]s).
    pub fn as_mesh_ref(&self) -> MeshRef<'_> {
        MeshRef {
            vertices: &self.vertices,
            triangles: &self.triangles,
            crs_wkt: self.crs_wkt.as_deref(),
            epsg: self.epsg,
            attributes: &[],
            colours: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const VERTICES: [[f64; 3]; 3] = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]];

    #[test]
    fn crs_is_written_on_one_trimmed_line() {
        let mesh =
            MeshRef::new(&VERTICES, &[]).with_crs_wkt("  GEOGCS[\"x\",\r\n  DATUM[\"y\"]\n]\r ");
        assert_eq!(
            mesh.crs_line().as_deref(),
            Some("GEOGCS[\"x\",   DATUM[\"y\"] ]")
        );
        assert_eq!(
            MeshRef::new(&VERTICES, &[]).with_crs_wkt(" \n").crs_line(),
            None
        );
        assert_eq!(MeshRef::new(&VERTICES, &[]).crs_line(), None);
    }

    #[test]
    fn check_rejects_out_of_range_indices() {
        let triangles = [[0, 1, 2], [2, 1, 3]];
        let error = MeshRef::new(&VERTICES, &triangles).check(Path::new("t.obj"), MeshFormat::Obj);
        match error {
            Err(Error::IndexOutOfRange {
                triangle: 1,
                index: 3,
                vertex_count: 3,
                ..
            }) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn check_rejects_non_finite_coordinates() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let vertices = [[0.0, 0.0, 0.0], [1.0, bad, 0.0]];
            let error = MeshRef::new(&vertices, &[]).check(Path::new("t.ply"), MeshFormat::Ply);
            assert!(
                matches!(error, Err(Error::NonFiniteVertex { vertex: 1, .. })),
                "{error:?}"
            );
        }
    }

    #[test]
    fn check_accepts_a_valid_mesh_and_an_empty_one() {
        let triangles = [[0, 1, 2]];
        assert!(MeshRef::new(&VERTICES, &triangles)
            .check(Path::new("t.ply"), MeshFormat::Ply)
            .is_ok());
        assert!(MeshRef::new(&[], &[])
            .check(Path::new("t.obj"), MeshFormat::Obj)
            .is_ok());
    }

    #[test]
    fn owned_mesh_borrows_back() {
        let mut mesh = Mesh::new(VERTICES.to_vec(), vec![[0, 1, 2]]);
        mesh.crs_wkt = Some("EPSG:4326".to_owned());
        let borrowed = mesh.as_mesh_ref();
        assert_eq!(borrowed.vertices, &VERTICES);
        assert_eq!(borrowed.crs_wkt, Some("EPSG:4326"));
    }
}
