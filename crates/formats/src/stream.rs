//! Writing a mesh piece by piece, for meshes too large to hold in memory at once.

use std::fs::File;
use std::io::{self, BufWriter, Seek, Write};
use std::path::{Path, PathBuf};

use tinsmith_output::write_atomically_with_sidecar;

use crate::error::{Error, Result};
use crate::format::MeshFormat;
use crate::mesh::MeshRef;

/// Size of each spool's write buffer.
const BUFFER_SIZE: usize = 1 << 16;

/// A mesh file written in pieces: vertices and triangles are appended as they come (for
/// example tile by tile), and the file appears, complete, when [`MeshStreamWriter::finish`]
/// succeeds.
///
/// Vertices and triangles are spooled to two unnamed temporary files in the output
/// directory (the system's temporary directory for a device or pipe; the PLY header needs
/// both counts before any record), which vanish however the process ends; `finish` writes
/// the header and both spools into a third temporary file and renames it over the target.
/// The file is byte for byte the one [`crate::write_mesh`] writes for the same vertices,
/// triangles and CRS.
///
/// # Guarantees
/// - **Atomic output.** Until `finish` returns `Ok`, nothing exists at the target path (or
///   its previous content is untouched). Dropping the writer, or any error, removes the
///   temporary files.
/// - **Checked input.** Each call checks what [`crate::write_mesh`] checks: finite
///   coordinates, indices below the number of vertices written *so far* (a triangle may only
///   refer to vertices appended before it), and for PLY at most 2^31 vertices.
///
/// # Example
/// ```
/// use tinsmith_formats::{read_mesh, MeshFormat, MeshStreamWriter};
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("welded.ply");
/// let mut writer = MeshStreamWriter::create(&path, MeshFormat::Ply, Some("EPSG:32633"))?;
/// writer.write_vertices(&[[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]])?;
/// writer.write_triangles(&[[0, 1, 2]])?;
/// writer.write_vertices(&[[1.0, 1.0, 4.0]])?;
/// writer.write_triangles(&[[1, 3, 2]])?;
/// writer.finish()?;
/// assert_eq!(read_mesh(&path)?.triangles, [[0, 1, 2], [1, 3, 2]]);
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct MeshStreamWriter {
    path: PathBuf,
    format: MeshFormat,
    crs_wkt: Option<String>,
    /// The WKT as given, for the `.prj` sidecar of formats that have one (OBJ).
    prj_wkt: Option<String>,
    vertices: Spool,
    triangles: Spool,
    vertex_count: usize,
    triangle_count: usize,
    /// Names of the per-vertex `double` properties after x, y, z (PLY).
    attribute_names: Vec<String>,
}

impl MeshStreamWriter {
    /// Starts a mesh file at `path` in `format`, with an optional CRS (written as
    /// [`MeshRef::with_crs_wkt`] describes).
    ///
    /// # Errors
    /// [`Error::MissingDirectory`] when `path`'s directory does not exist; [`Error::Io`]
    /// when the temporary files cannot be created there.
    pub fn create(
        path: &Path,
        format: MeshFormat,
        crs_wkt: Option<&str>,
    ) -> Result<MeshStreamWriter> {
        if !matches!(format, MeshFormat::Ply | MeshFormat::Obj) {
            return Err(Error::Unsupported {
                path: path.to_path_buf(),
                format,
                feature: "streamed (tiled) output is written as PLY or OBJ only".into(),
            });
        }
        let dir = match path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        };
        if !dir.exists() {
            return Err(Error::MissingDirectory {
                path: path.to_path_buf(),
                dir: dir.to_path_buf(),
            });
        }
        // A device or pipe (`/dev/stdout`) has no directory of its own to spool in.
        let spool_dir = if tinsmith_output::is_special_file(path) {
            std::env::temp_dir()
        } else {
            dir.to_path_buf()
        };
        let spool = || {
            Spool::new(&spool_dir).map_err(|source| Error::Io {
                path: path.to_path_buf(),
                action: "create a temporary file in the output directory",
                source,
            })
        };
        Ok(MeshStreamWriter {
            path: path.to_path_buf(),
            format,
            crs_wkt: MeshRef::new(&[], &[]).with_crs_wkt(crs_wkt).crs_line(),
            prj_wkt: crs_wkt
                .filter(|w| !w.trim().is_empty() && format.uses_prj_sidecar())
                .map(str::to_owned),
            vertices: spool()?,
            triangles: spool()?,
            vertex_count: 0,
            triangle_count: 0,
            attribute_names: Vec::new(),
        })
    }

    /// The writer with one `double` vertex property per name after x, y, z, as
    /// [`crate::write_mesh`] writes [`crate::VertexAttribute`]s (same header and records):
    /// vertices are then appended with [`Self::write_vertices_with_attributes`]. PLY only.
    ///
    /// # Errors
    /// [`Error::Unsupported`] for OBJ (it carries no per-vertex values).
    pub fn with_attribute_names(mut self, names: Vec<String>) -> Result<MeshStreamWriter> {
        if !names.is_empty() && self.format != MeshFormat::Ply {
            return Err(Error::Unsupported {
                path: self.path.clone(),
                format: self.format,
                feature: "streamed per-vertex values are written as PLY only".into(),
            });
        }
        self.attribute_names = names;
        Ok(self)
    }

    /// The target path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Vertices appended so far: the index the next vertex gets.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Triangles appended so far.
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Appends vertices (world x, y, z); they get the next indices in order.
    ///
    /// # Errors
    /// [`Error::NonFiniteVertex`] (the vertex index counts every vertex appended before),
    /// [`Error::TooManyVertices`] (PLY), [`Error::Io`]. After an error the writer should
    /// be dropped.
    pub fn write_vertices(&mut self, vertices: &[[f64; 3]]) -> Result<()> {
        self.write_vertices_with_attributes(vertices, &[])
    }

    /// Appends vertices with their values of each attribute named by
    /// [`Self::with_attribute_names`] (`attributes[k][i]`: attribute `k` of vertex `i`).
    ///
    /// # Errors
    /// As [`Self::write_vertices`]; [`Error::Io`] (`InvalidInput`) when `attributes` does
    /// not hold one list of one value per vertex for each name.
    pub fn write_vertices_with_attributes(
        &mut self,
        vertices: &[[f64; 3]],
        attributes: &[&[f64]],
    ) -> Result<()> {
        if attributes.len() != self.attribute_names.len()
            || attributes.iter().any(|a| a.len() != vertices.len())
        {
            let problem = format!(
                "{} attribute lists for {} names and {} vertices",
                attributes.len(),
                self.attribute_names.len(),
                vertices.len()
            );
            return Err(self.io_error(
                "write",
                io::Error::new(io::ErrorKind::InvalidInput, problem),
            ));
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(Error::NonFiniteVertex {
                path: self.path.clone(),
                vertex: self.vertex_count + i,
                position: vertices[i],
            });
        }
        let count = self.vertex_count + vertices.len();
        let max = i32::MAX as usize + 1;
        if self.format == MeshFormat::Ply && count > max {
            return Err(Error::TooManyVertices {
                path: self.path.clone(),
                format: self.format,
                count,
                max,
            });
        }
        let w = &mut self.vertices.writer;
        let result = match self.format {
            MeshFormat::Ply if !attributes.is_empty() => {
                let mut record = vec![0u8; 8 * (3 + attributes.len())];
                vertices.iter().enumerate().try_for_each(|(i, vertex)| {
                    let values = vertex
                        .iter()
                        .copied()
                        .chain(attributes.iter().map(|a| a[i]));
                    for (bytes, value) in record.chunks_exact_mut(8).zip(values) {
                        bytes.copy_from_slice(&value.to_le_bytes());
                    }
                    w.write_all(&record)
                })
            }
            MeshFormat::Ply => vertices.iter().try_for_each(|vertex| {
                let mut record = [0u8; 24];
                for (bytes, coordinate) in record.chunks_exact_mut(8).zip(vertex) {
                    bytes.copy_from_slice(&coordinate.to_le_bytes());
                }
                w.write_all(&record)
            }),
            // Only PLY and OBJ get here (`create` refuses the others).
            _ => vertices
                .iter()
                .try_for_each(|[x, y, z]| writeln!(w, "v {x:?} {y:?} {z:?}")),
        };
        result.map_err(|source| self.io_error("write", source))?;
        self.vertex_count = count;
        Ok(())
    }

    /// Appends triangles, as 0-based indices of vertices already appended, in the
    /// orientation to be written.
    ///
    /// # Errors
    /// [`Error::IndexOutOfRange`] when an index is not below [`Self::vertex_count`] (the
    /// triangle number counts every triangle appended before), [`Error::Io`]. After an
    /// error the writer should be dropped.
    pub fn write_triangles(&mut self, triangles: &[[u32; 3]]) -> Result<()> {
        let vertex_count = self.vertex_count;
        for (i, corners) in triangles.iter().enumerate() {
            if let Some(&index) = corners.iter().find(|&&c| c as usize >= vertex_count) {
                return Err(Error::IndexOutOfRange {
                    path: self.path.clone(),
                    triangle: self.triangle_count + i,
                    index,
                    vertex_count,
                });
            }
        }
        let w = &mut self.triangles.writer;
        let result = match self.format {
            // Indices are below the vertex count, which is at most 2^31: they fit an `int`.
            MeshFormat::Ply => triangles.iter().try_for_each(|triangle| {
                let mut record = [0u8; 13];
                record[0] = 3;
                for (bytes, &index) in record[1..].chunks_exact_mut(4).zip(triangle) {
                    bytes.copy_from_slice(&(index as i32).to_le_bytes());
                }
                w.write_all(&record)
            }),
            _ => triangles.iter().try_for_each(|&[a, b, c]| {
                writeln!(
                    w,
                    "f {} {} {}",
                    u64::from(a) + 1,
                    u64::from(b) + 1,
                    u64::from(c) + 1
                )
            }),
        };
        result.map_err(|source| self.io_error("write", source))?;
        self.triangle_count += triangles.len();
        Ok(())
    }

    /// Writes the file: header, then every vertex, then every triangle, through a
    /// temporary file renamed over the target, with the `.prj` sidecar as
    /// [`crate::write_mesh`] writes it (OBJ). The spools are removed in any case.
    ///
    /// # Errors
    /// [`Error::Io`] as [`crate::write_mesh`]; the target is then untouched.
    pub fn finish(mut self) -> Result<()> {
        let mut vertices = self
            .vertices
            .rewind()
            .map_err(|source| self.io_error("write", source))?;
        let mut triangles = self
            .triangles
            .rewind()
            .map_err(|source| self.io_error("write", source))?;
        let header = self.header();
        let prj = crate::prj_path(&self.path);
        let sidecar = self
            .prj_wkt
            .as_deref()
            .map(|wkt| (prj.as_path(), wkt.as_bytes()));
        write_atomically_with_sidecar(
            &self.path,
            |w| {
                w.write_all(header.as_bytes())?;
                io::copy(&mut vertices, w)?;
                io::copy(&mut triangles, w)?;
                Ok(())
            },
            sidecar,
        )
        .map_err(Error::from)
    }

    /// The header [`crate::write_mesh`] writes for a mesh of the counts so far.
    fn header(&self) -> String {
        match self.format {
            MeshFormat::Ply => {
                let mut header = String::from(
                    "ply\nformat binary_little_endian 1.0\ncomment generated by tinsmith\n",
                );
                if let Some(crs) = &self.crs_wkt {
                    header.push_str(&format!("comment crs {crs}\n"));
                }
                header.push_str(&format!(
                    "element vertex {}\nproperty double x\nproperty double y\n\
                     property double z\n",
                    self.vertex_count
                ));
                for name in &self.attribute_names {
                    header.push_str(&format!("property double {name}\n"));
                }
                header.push_str(&format!(
                    "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                    self.triangle_count
                ));
                header
            }
            _ => match &self.crs_wkt {
                Some(crs) => format!("# tinsmith\n# crs: {crs}\n"),
                None => "# tinsmith\n".to_owned(),
            },
        }
    }

    fn io_error(&self, action: &'static str, source: io::Error) -> Error {
        Error::Io {
            path: self.path.clone(),
            action,
            source,
        }
    }
}

/// An unnamed temporary file with a buffered writer.
///
/// The file has no name in the output directory (`O_TMPFILE` on Linux; elsewhere it is
/// unlinked right after creation), so it vanishes when its handles close, however the
/// process ends: killed, aborted on a failed allocation, or out of disk.
#[derive(Debug)]
struct Spool {
    file: File,
    writer: BufWriter<File>,
}

impl Spool {
    fn new(dir: &Path) -> io::Result<Spool> {
        let file = tinsmith_output::unnamed_temp_file(dir)?;
        let writer = BufWriter::with_capacity(BUFFER_SIZE, file.try_clone()?);
        Ok(Spool { file, writer })
    }

    /// Flushes the writer and returns a handle reading the spool from its start.
    fn rewind(&mut self) -> io::Result<File> {
        self.writer.flush()?;
        let mut file = self.file.try_clone()?;
        file.rewind()?;
        Ok(file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The formats the stream writer writes; it refuses the others.
    const STREAMED: [MeshFormat; 2] = [MeshFormat::Ply, MeshFormat::Obj];
    use crate::{write_mesh, VertexAttribute};

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("read dir")
            .map(|e| e.expect("entry").path())
            .collect();
        entries.sort();
        entries
    }

    fn sample_mesh() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let vertices = (0..40)
            .map(|i| [i as f64 * 0.1, (i % 7) as f64 * 1e-300, -3.25 * i as f64])
            .collect();
        let triangles = (0..37).map(|i| [i, i + 1, i + 2]).collect();
        (vertices, triangles)
    }

    #[test]
    fn pieces_with_attributes_give_the_bytes_write_mesh_gives() -> Result<()> {
        let dir = tempfile::tempdir().expect("tempdir");
        let (vertices, triangles) = sample_mesh();
        let a: Vec<f64> = (0..40).map(|i| f64::from(i) * 0.5 - 3.0).collect();
        let b: Vec<f64> = (0..40).map(|i| f64::from(i * i) / 7.0).collect();
        let attributes = [
            VertexAttribute {
                name: "band_2",
                values: &a,
            },
            VertexAttribute {
                name: "temp",
                values: &b,
            },
        ];
        let whole = dir.path().join("whole.ply");
        let pieces = dir.path().join("pieces.ply");
        write_mesh(
            &whole,
            MeshFormat::Ply,
            MeshRef::new(&vertices, &triangles).with_attributes(&attributes),
        )?;
        let mut w = MeshStreamWriter::create(&pieces, MeshFormat::Ply, None)?
            .with_attribute_names(vec!["band_2".into(), "temp".into()])?;
        w.write_vertices_with_attributes(&vertices[..3], &[&a[..3], &b[..3]])?;
        w.write_triangles(&triangles[..1])?;
        w.write_vertices_with_attributes(&vertices[3..], &[&a[3..], &b[3..]])?;
        w.write_triangles(&triangles[1..])?;
        // A list short of the vertices, or none at all, is refused.
        assert!(w.write_vertices(&vertices[..1]).is_err());
        assert!(w
            .write_vertices_with_attributes(&vertices[..2], &[&a[..2], &b[..1]])
            .is_err());
        w.finish()?;
        assert_eq!(
            std::fs::read(&whole).expect("whole"),
            std::fs::read(&pieces).expect("pieces")
        );
        let obj = MeshStreamWriter::create(&dir.path().join("m.obj"), MeshFormat::Obj, None)?;
        assert!(obj.with_attribute_names(vec!["band_2".into()]).is_err());
        Ok(())
    }

    #[test]
    fn pieces_give_the_bytes_write_mesh_gives() -> Result<()> {
        let dir = tempfile::tempdir().expect("tempdir");
        let (vertices, triangles) = sample_mesh();
        for format in STREAMED {
            for crs in [None, Some("PROJCS[\"x\",\n UNIT[\"m\"]]")] {
                let whole = dir.path().join(format!("whole.{}", format.extension()));
                let pieces = dir.path().join(format!("pieces.{}", format.extension()));
                write_mesh(
                    &whole,
                    format,
                    MeshRef::new(&vertices, &triangles).with_crs_wkt(crs),
                )?;
                let mut w = MeshStreamWriter::create(&pieces, format, crs)?;
                // Interleaved: each triangle only after its vertices.
                w.write_vertices(&vertices[..3])?;
                w.write_triangles(&triangles[..1])?;
                w.write_vertices(&vertices[3..25])?;
                w.write_triangles(&triangles[1..20])?;
                w.write_triangles(&[])?;
                w.write_vertices(&vertices[25..])?;
                w.write_triangles(&triangles[20..])?;
                assert_eq!((w.vertex_count(), w.triangle_count()), (40, 37));
                w.finish()?;
                assert_eq!(
                    std::fs::read(&whole).expect("whole"),
                    std::fs::read(&pieces).expect("pieces"),
                    "{format:?} {crs:?}"
                );
            }
        }
        Ok(())
    }

    #[test]
    fn nothing_appears_before_finish_and_nothing_stays_after_drop() -> Result<()> {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.ply");
        let mut w = MeshStreamWriter::create(&path, MeshFormat::Ply, None)?;
        w.write_vertices(&[[0.0; 3]; 5])?;
        // The spools have no names: a run killed now (no drop) leaves nothing behind.
        assert!(entries(dir.path()).is_empty());
        drop(w);
        assert!(entries(dir.path()).is_empty());

        std::fs::write(&path, b"old").expect("seed");
        let mut w = MeshStreamWriter::create(&path, MeshFormat::Obj, None)?;
        w.write_vertices(&[[0.0; 3]; 3])?;
        let err = w.write_triangles(&[[0, 1, 3]]).expect_err("index 3");
        assert!(
            matches!(
                err,
                Error::IndexOutOfRange {
                    triangle: 0,
                    index: 3,
                    vertex_count: 3,
                    ..
                }
            ),
            "{err:?}"
        );
        drop(w);
        assert_eq!(std::fs::read(&path).expect("old"), b"old");
        assert_eq!(entries(dir.path()), vec![path]);
        Ok(())
    }

    #[test]
    fn bad_input_is_reported_with_running_numbers() -> Result<()> {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("out.ply");
        let mut w = MeshStreamWriter::create(&path, MeshFormat::Ply, None)?;
        w.write_vertices(&[[0.0; 3]; 4])?;
        w.write_triangles(&[[0, 1, 2]])?;
        let err = w
            .write_vertices(&[[0.0; 3], [1.0, f64::NAN, 0.0]])
            .expect_err("NaN");
        assert!(
            matches!(err, Error::NonFiniteVertex { vertex: 5, .. }),
            "{err:?}"
        );
        let err = w.write_triangles(&[[0, 1, 2], [3, 2, 4]]).expect_err("4");
        assert!(
            matches!(
                err,
                Error::IndexOutOfRange {
                    triangle: 2,
                    index: 4,
                    ..
                }
            ),
            "{err:?}"
        );
        Ok(())
    }

    #[test]
    fn other_formats_are_refused_up_front() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.stl");
        let Err(err) = MeshStreamWriter::create(&path, MeshFormat::Stl, None) else {
            panic!("STL accepted for streaming");
        };
        assert!(err.to_string().contains("PLY or OBJ"), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn missing_directory_is_named() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("no/such/out.ply");
        let err = MeshStreamWriter::create(&path, MeshFormat::Ply, None).expect_err("missing");
        assert!(matches!(err, Error::MissingDirectory { .. }), "{err:?}");
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn empty_mesh_is_a_valid_file() -> Result<()> {
        let dir = tempfile::tempdir().expect("tempdir");
        for format in STREAMED {
            let path = dir.path().join(format!("empty.{}", format.extension()));
            MeshStreamWriter::create(&path, format, None)?.finish()?;
            let mesh = crate::read_mesh(&path)?;
            assert!(mesh.vertices.is_empty() && mesh.triangles.is_empty());
        }
        Ok(())
    }
}
