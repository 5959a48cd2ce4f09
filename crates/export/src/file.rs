//! Writing and reading mesh files by path: format dispatch, validation and error context.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use crate::atomic::write_atomically;
use crate::error::{Error, Problem, Result};
use crate::format::MeshFormat;
use crate::mesh::{Mesh, MeshRef};
use crate::{obj, ply};

/// Size of the read buffer.
const BUFFER_SIZE: usize = 1 << 16;

/// Writes `mesh` to `path` in `format`, atomically.
///
/// The file is written to a temporary file in the same directory and renamed over `path`
/// once complete, so readers never see a partial file. An existing file at `path` is
/// replaced.
///
/// Reading the file back with [`read_mesh`] gives the same vertices (bit for bit), the same
/// triangles in the same order and orientation, and the CRS as described in
/// [`MeshRef::with_crs_wkt`].
///
/// # Errors
/// - [`Error::MissingDirectory`] if `path`'s directory does not exist.
/// - [`Error::IndexOutOfRange`], [`Error::NonFiniteVertex`], [`Error::TooManyVertices`] if
///   the mesh cannot be written as a valid file; these are found before any file is created.
/// - [`Error::Io`] if the directory is not writable, the disk is full, `path` is a
///   directory, …; the I/O error is the source.
///
/// After an error, nothing new is left on disk: no file at `path` (or its previous content,
/// untouched) and no temporary file.
///
/// # Example
/// ```no_run
/// use std::path::Path;
/// use tinsmith_export::{write_mesh, MeshFormat, MeshRef};
/// # fn main() -> tinsmith_export::Result<()> {
/// let vertices = [[0.0, 0.0, 10.0], [30.0, 0.0, 12.5], [0.0, 30.0, 11.0]];
/// let triangles = [[0, 1, 2]];
/// let path = Path::new("out/tile.obj");
/// write_mesh(path, MeshFormat::from_path(path)?, MeshRef::new(&vertices, &triangles))?;
/// # Ok(())
/// # }
/// ```
pub fn write_mesh(path: &Path, format: MeshFormat, mesh: MeshRef<'_>) -> Result<()> {
    mesh.check(path, format)?;
    write_atomically(path, |w| match format {
        MeshFormat::Ply => ply::write(w, mesh),
        MeshFormat::Obj => obj::write(w, mesh),
    })
}

/// Reads the mesh file at `path`, choosing the format by its extension (see
/// [`MeshFormat::from_path`]).
///
/// PLY files may be ASCII or binary (either byte order), with `x`, `y`, `z` vertex
/// properties of any numeric type in any order among other properties, and a face list
/// named `vertex_indices` or `vertex_index` with integer count and index types. OBJ files
/// are read as described in [`MeshFormat::Obj`]; see [`read_mesh_as`] for both.
///
/// The returned mesh has finite coordinates only and every index is below the vertex count.
///
/// # Errors
/// - [`Error::UnknownExtension`] if the extension is not a supported one.
/// - Any error of [`read_mesh_as`].
///
/// # Example
/// ```no_run
/// # fn main() -> tinsmith_export::Result<()> {
/// let mesh = tinsmith_export::read_mesh(std::path::Path::new("tests/data/tile.ply"))?;
/// println!("{} vertices, {} triangles", mesh.vertices.len(), mesh.triangles.len());
/// # Ok(())
/// # }
/// ```
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    read_mesh_as(path, MeshFormat::from_path(path)?)
}

/// Reads the mesh file at `path` as `format`, whatever its extension.
///
/// Only triangle faces are read. Other PLY elements (edges, materials) and OBJ statements
/// that carry no vertex or triangle (`vt`, `vn`, `g`, `usemtl`, …) are skipped; data after
/// the last PLY element is ignored. The CRS comes from the first `comment crs <wkt>` (PLY)
/// or `# crs: <wkt>` (OBJ) line, trimmed.
///
/// # Errors
/// Every error names `path`:
/// - [`Error::Io`] if the file cannot be opened or read.
/// - [`Error::Malformed`] for an empty file, a bad header, truncated data, text where a
///   number belongs, an index out of range or a non-finite coordinate; the reason says
///   where.
/// - [`Error::Unsupported`] for a face that is not a triangle or an unknown PLY encoding.
///
/// Malformed input gives an error, never a panic, and header counts are checked against the
/// file size before memory is reserved for them.
pub fn read_mesh_as(path: &Path, format: MeshFormat) -> Result<Mesh> {
    let file = File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        action: "open",
        source,
    })?;
    let file_len = file.metadata().ok().map(|metadata| metadata.len());
    let reader = BufReader::with_capacity(BUFFER_SIZE, file);
    let result: std::result::Result<Mesh, Problem> = match format {
        MeshFormat::Ply => ply::read(reader, file_len),
        MeshFormat::Obj => obj::read(reader),
    };
    result.map_err(|problem| problem.at(path, format))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn bits(vertices: &[[f64; 3]]) -> Vec<u64> {
        vertices.iter().flatten().map(|c| c.to_bits()).collect()
    }

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("read test dir")
            .map(|entry| entry.expect("dir entry").path())
            .collect();
        entries.sort();
        entries
    }

    /// Awkward values: tiny, UTM-sized, float-range, inexact sums, signed zero.
    const VERTICES: [[f64; 3]; 5] = [
        [1e-300, 5e-324, -0.0],
        [500_000.0, 4_649_776.25, 5e6],
        [-3.4e38, 3.4e38, f64::MAX],
        [0.1 + 0.2, 0.1, 1.0 / 3.0],
        [512_345.678_9, 5_123_456.789_012_3, 2_962.125],
    ];
    const TRIANGLES: [[u32; 3]; 3] = [[0, 1, 2], [2, 3, 0], [4, 3, 2]];
    const WKT: &str = "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\"],\
                       AUTHORITY[\"EPSG\",\"32633\"]]";

    #[test]
    fn round_trip_is_bit_exact_in_every_format() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        for format in MeshFormat::ALL {
            let path = dir.path().join(format!("tile.{}", format.extension()));
            let mesh = MeshRef::new(&VERTICES, &TRIANGLES).with_crs_wkt(WKT);
            write_mesh(&path, format, mesh)?;
            let back = read_mesh(&path)?;
            assert_eq!(bits(&back.vertices), bits(&VERTICES), "{format}");
            assert_eq!(back.triangles, TRIANGLES, "{format}");
            assert_eq!(back.crs_wkt.as_deref(), Some(WKT), "{format}");
            // And once more from the owned mesh: same bytes.
            let again = dir.path().join(format!("again.{}", format.extension()));
            write_mesh(&again, format, back.as_mesh_ref())?;
            assert_eq!(
                std::fs::read(&path).ok(),
                std::fs::read(&again).ok(),
                "{format}"
            );
        }
        Ok(())
    }

    #[test]
    fn multi_line_crs_comes_back_on_one_line() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let wkt = "GEOGCS[\"WGS 84\",\n    DATUM[\"WGS_1984\"],\r\n    UNIT[\"degree\",0.01]]\n";
        for format in MeshFormat::ALL {
            let path = dir.path().join(format!("crs.{}", format.extension()));
            write_mesh(
                &path,
                format,
                MeshRef::new(&VERTICES, &[]).with_crs_wkt(wkt),
            )?;
            let back = read_mesh(&path)?;
            assert_eq!(
                back.crs_wkt.as_deref(),
                Some("GEOGCS[\"WGS 84\",     DATUM[\"WGS_1984\"],     UNIT[\"degree\",0.01]]"),
                "{format}"
            );
            write_mesh(&path, format, MeshRef::new(&VERTICES, &[]))?;
            assert_eq!(read_mesh(&path)?.crs_wkt, None, "{format}");
        }
        Ok(())
    }

    #[test]
    fn success_leaves_only_the_output() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let ply = dir.path().join("a.ply");
        let obj = dir.path().join("b.obj");
        write_mesh(&ply, MeshFormat::Ply, MeshRef::new(&VERTICES, &TRIANGLES))?;
        write_mesh(&obj, MeshFormat::Obj, MeshRef::new(&VERTICES, &TRIANGLES))?;
        assert_eq!(entries(dir.path()), vec![ply, obj]);
        Ok(())
    }

    #[test]
    fn missing_directory_leaves_nothing() {
        let dir = tempfile::tempdir().expect("temp dir");
        let missing = dir.path().join("missing");
        let path = missing.join("tile.ply");
        let result = write_mesh(&path, MeshFormat::Ply, MeshRef::new(&VERTICES, &TRIANGLES));
        let message = result.err().map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(
            message,
            format!(
                "{}: output directory {} does not exist",
                path.display(),
                missing.display()
            )
        );
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn invalid_mesh_creates_no_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("tile.obj");
        let result = write_mesh(
            &path,
            MeshFormat::Obj,
            MeshRef::new(&VERTICES, &[[0, 1, 5]]),
        );
        assert!(
            matches!(result, Err(Error::IndexOutOfRange { index: 5, .. })),
            "{result:?}"
        );
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn unwritable_target_names_the_path_and_keeps_the_cause() {
        let dir = tempfile::tempdir().expect("temp dir");
        // A directory where the file should go: the final rename fails.
        let path = dir.path().join("tile.ply");
        std::fs::create_dir(&path).expect("mkdir");
        let result = write_mesh(&path, MeshFormat::Ply, MeshRef::new(&VERTICES, &TRIANGLES));
        let error = result.expect_err("writing over a directory fails");
        assert!(
            error.to_string().starts_with(&path.display().to_string()),
            "{error}"
        );
        assert!(std::error::Error::source(&error).is_some());
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn read_errors_name_the_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let missing = dir.path().join("nope.ply");
        let error = read_mesh(&missing).expect_err("missing file");
        assert!(
            matches!(error, Error::Io { action: "open", .. }),
            "{error:?}"
        );
        assert!(error.to_string().contains("nope.ply"));

        let unknown = dir.path().join("tile.stl");
        std::fs::write(&unknown, b"solid").expect("seed");
        let error = read_mesh(&unknown).expect_err("unknown extension");
        assert!(matches!(error, Error::UnknownExtension { .. }), "{error:?}");
        assert!(error.to_string().contains("tile.stl"));

        let empty = dir.path().join("empty.obj");
        std::fs::write(&empty, b"").expect("seed");
        let error = read_mesh(&empty).expect_err("empty file");
        assert_eq!(
            error.to_string(),
            format!("{}: invalid OBJ file: the file is empty", empty.display())
        );
    }

    #[test]
    fn read_mesh_as_ignores_the_extension() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("tile.bin");
        std::fs::write(&path, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("seed");
        assert_eq!(
            read_mesh_as(&path, MeshFormat::Obj)?.triangles,
            vec![[0, 1, 2]]
        );
        Ok(())
    }
}
