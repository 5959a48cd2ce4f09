//! Writing and reading mesh files by path: format dispatch, validation and error context.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use tinsmith_output::write_atomically_with_sidecar;

use crate::error::{Error, Problem, Result};
use crate::format::MeshFormat;
use crate::mesh::{Mesh, MeshRef};
use crate::options::WriteOptions;
use crate::origin::LocalOrigin;
use crate::{fgb, geojson, glb, landxml, obj, ply, stl};

/// Size of the read buffer.
const BUFFER_SIZE: usize = 1 << 16;

/// Writes `mesh` to `path` in `format` with the default [`WriteOptions`], atomically; see
/// [`write_mesh_with`].
///
/// # Example
/// ```no_run
/// use std::path::Path;
/// use tinsmith_formats::{write_mesh, MeshFormat, MeshRef};
/// # fn main() -> tinsmith_formats::Result<()> {
/// let vertices = [[0.0, 0.0, 10.0], [30.0, 0.0, 12.5], [0.0, 30.0, 11.0]];
/// let triangles = [[0, 1, 2]];
/// let path = Path::new("out/tile.obj");
/// write_mesh(path, MeshFormat::from_path(path)?, MeshRef::new(&vertices, &triangles))?;
/// # Ok(())
/// # }
/// ```
pub fn write_mesh(path: &Path, format: MeshFormat, mesh: MeshRef<'_>) -> Result<()> {
    write_mesh_with(path, format, mesh, &WriteOptions::default())
}

/// The `.prj` sidecar of `path`: the same name with the extension `prj`.
pub fn prj_path(path: &Path) -> PathBuf {
    path.with_extension("prj")
}

/// Writes `mesh` to `path` in `format`, atomically, with format-specific `options`.
///
/// The file is written to a temporary file in the same directory and renamed over `path`
/// once complete, so readers never see a partial file. An existing file at `path` is
/// replaced. Every format is written as a stream from the slices: no second copy of the
/// mesh is made (FlatGeobuf keeps one index entry per triangle; STL with a base keeps the
/// list of edges to find the boundary; glTF with normals keeps one normal per vertex).
///
/// The CRS is recorded where the format holds one (see [`MeshFormat`]); for OBJ, STL and
/// glTF the WKT is also written, verbatim, to the `.prj` sidecar ([`prj_path`]), renamed
/// into place just before the mesh.
///
/// Reading the file back with [`read_mesh`] gives the same triangles in the same order and
/// orientation, and the same vertices: bit for bit for the `f64` formats (PLY, OBJ,
/// GeoJSON, FlatGeobuf, LandXML); [`LocalOrigin::quantize`] of them for the float32
/// formats (STL, glTF), with the origin of `options` or [`LocalOrigin::of_points`].
/// Formats that store corners by value (STL, GeoJSON, FlatGeobuf) give back each distinct
/// position once, in order of first use by the triangles.
///
/// # Errors
/// - [`Error::MissingDirectory`] if `path`'s directory does not exist.
/// - [`Error::IndexOutOfRange`], [`Error::NonFiniteVertex`], [`Error::TooManyVertices`],
///   [`Error::TooManyTriangles`] if the mesh cannot be written as a valid file, and
///   [`Error::BadOption`] for an STL base not below every vertex; these are found before
///   any file is created.
/// - [`Error::Io`] if the directory is not writable, the disk is full, `path` is a
///   directory, …; the I/O error is the source.
///
/// After an error, nothing new is left on disk: no file at `path` (or its previous content,
/// untouched), no sidecar and no temporary file.
pub fn write_mesh_with(
    path: &Path,
    format: MeshFormat,
    mesh: MeshRef<'_>,
    options: &WriteOptions,
) -> Result<()> {
    mesh.check(path, format)?;
    let origin = options
        .origin()
        .unwrap_or_else(|| LocalOrigin::of_points(mesh.vertices));
    if format.is_float32() {
        check_float32(path, mesh, origin)?;
    }
    let base = match format {
        MeshFormat::Stl => check_stl(path, mesh, origin, options.base())?,
        _ => None,
    };
    let prj = prj_path(path);
    let wkt = mesh.crs_wkt.filter(|w| !w.trim().is_empty());
    let sidecar = match wkt {
        Some(wkt) if format.uses_prj_sidecar() => Some((prj.as_path(), wkt.as_bytes())),
        _ => None,
    };
    write_atomically_with_sidecar(
        path,
        |w| match format {
            MeshFormat::Ply => ply::write(w, mesh),
            MeshFormat::Obj => obj::write(w, mesh),
            MeshFormat::Stl => stl::write(w, mesh, origin, base),
            MeshFormat::Glb => glb::write(w, mesh, origin, options.normals()),
            MeshFormat::GeoJson => geojson::write(w, mesh),
            MeshFormat::FlatGeobuf => fgb::write(w, mesh),
            MeshFormat::LandXml => landxml::write(w, mesh),
        },
        sidecar,
    )
    .map_err(Error::from)
}

/// Checks that every vertex is finite relative to `origin` in float32.
fn check_float32(path: &Path, mesh: MeshRef<'_>, origin: LocalOrigin) -> Result<()> {
    if let Some(vertex) = mesh
        .vertices
        .iter()
        .position(|&p| !origin.to_local(p).iter().all(|c| c.is_finite()))
    {
        return Err(Error::BadOption {
            path: path.to_path_buf(),
            reason: format!(
                "vertex {vertex} {:?} is too far from the origin {:?} for float32",
                mesh.vertices[vertex],
                origin.offset()
            ),
        });
    }
    Ok(())
}

/// Checks what the STL writer needs: a facet count that fits a `u32`, a header that fits,
/// a base below every vertex after float32 rounding. Returns the base.
fn check_stl(
    path: &Path,
    mesh: MeshRef<'_>,
    origin: LocalOrigin,
    base: Option<f64>,
) -> Result<Option<f64>> {
    let count = match base {
        Some(_) => stl::solid_facet_count(mesh.triangles),
        None => mesh.triangles.len() as u64,
    };
    if count > u64::from(u32::MAX) {
        return Err(Error::TooManyTriangles {
            path: path.to_path_buf(),
            format: MeshFormat::Stl,
            count,
            max: u64::from(u32::MAX),
        });
    }
    if stl::header_text(origin, base).is_none() {
        return Err(Error::BadOption {
            path: path.to_path_buf(),
            reason: format!(
                "the origin {:?} does not fit in the 80-byte STL header",
                origin.offset()
            ),
        });
    }
    if let Some(base) = base {
        let local = |z: f64| origin.to_local([0.0, 0.0, z])[2];
        let lowest = mesh.vertices.iter().map(|v| v[2]).reduce(f64::min);
        let ok = base.is_finite() && lowest.is_none_or(|low| local(base) < local(low));
        if !ok {
            return Err(Error::BadOption {
                path: path.to_path_buf(),
                reason: format!(
                    "the STL base {base} must be below the lowest vertex ({}), also in float32",
                    lowest.unwrap_or(f64::NAN)
                ),
            });
        }
    }
    Ok(base)
}

/// Reads the mesh file at `path`, choosing the format by its extension (see
/// [`MeshFormat::from_path`]).
///
/// PLY files may be ASCII or binary (either byte order), with `x`, `y`, `z` vertex
/// properties of any numeric type in any order among other properties, and a face list
/// named `vertex_indices` or `vertex_index` with integer count and index types. See
/// [`read_mesh_as`] for every format.
///
/// The returned mesh has finite coordinates only and every index is below the vertex count.
///
/// # Errors
/// - [`Error::UnknownExtension`] if the extension is not a supported one.
/// - Any error of [`read_mesh_as`].
///
/// # Example
/// ```no_run
/// # fn main() -> tinsmith_formats::Result<()> {
/// let mesh = tinsmith_formats::read_mesh(std::path::Path::new("tests/data/tile.ply"))?;
/// println!("{} vertices, {} triangles", mesh.vertices.len(), mesh.triangles.len());
/// # Ok(())
/// # }
/// ```
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    read_mesh_as(path, MeshFormat::from_path(path)?)
}

/// Reads the mesh file at `path` as `format`, whatever its extension.
///
/// Only triangles are read:
/// - PLY: other elements (edges, materials) are skipped; data after the last element is
///   ignored. OBJ: statements that carry no vertex or triangle (`vt`, `vn`, `g`, `usemtl`,
///   …) are skipped. The CRS comes from the first `comment crs <wkt>` (PLY) or
///   `# crs: <wkt>` (OBJ) line, trimmed.
/// - STL: binary only. Positions are the header's `tinsmith origin X Y Z` (zero when the
///   header has none) plus the float32 corners; facets with a corner at the header's
///   `base` height (walls and bottom of a solid) are skipped.
/// - glTF (`.glb`): nodes with a translation only, triangle primitives, glTF axes mapped
///   back to world axes as the writer maps them (see [`MeshFormat::Glb`]).
/// - GeoJSON: `Polygon` Z features with a closed ring of 4 positions. Without a `crs`
///   member the coordinates are RFC 7946 longitude, latitude and [`Mesh::epsg`] is 4326.
/// - FlatGeobuf: `Triangle`, one-ring `Polygon` or `TIN` Z features, put back in `id`
///   order when every feature has one.
/// - LandXML: the first `Surface`'s points (northing easting elevation, any ids) and
///   visible faces.
///
/// For OBJ, STL and glTF files that record no CRS themselves, the CRS is read from the
/// `.prj` sidecar ([`prj_path`]) when there is one, on one line.
///
/// # Errors
/// Every error names `path`:
/// - [`Error::Io`] if the file cannot be opened or read.
/// - [`Error::Malformed`] for an empty file, a bad header, truncated data, text where a
///   number belongs, an index out of range or a non-finite coordinate; the reason says
///   where.
/// - [`Error::Unsupported`] for faces that are not triangles, 2D coordinates, an ASCII
///   STL, glTF nodes with rotation or scale, and the like.
///
/// Malformed input gives an error, never a panic, and header counts are checked against the
/// file size before memory is reserved for them.
pub fn read_mesh_as(path: &Path, format: MeshFormat) -> Result<Mesh> {
    let file = File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        action: "open",
        source,
    })?;
    // Only a regular file's length is its content's: a pipe or device reports 0.
    let file_len = file
        .metadata()
        .ok()
        .filter(|metadata| metadata.is_file())
        .map(|metadata| metadata.len());
    let reader = BufReader::with_capacity(BUFFER_SIZE, file);
    let mut mesh =
        read_from(reader, file_len, format).map_err(|problem| problem.at(path, format))?;
    if mesh.crs_wkt.is_none() && format.uses_prj_sidecar() {
        if let Ok(wkt) = std::fs::read_to_string(prj_path(path)) {
            mesh.crs_wkt = MeshRef::new(&[], &[]).with_crs_wkt(wkt.as_str()).crs_line();
        }
    }
    Ok(mesh)
}

/// Reads a mesh of `format` from `bytes`, as [`read_mesh_as`] reads a file with that
/// content; `name` is the file name the errors give (nothing is opened, and no `.prj`
/// sidecar is read).
///
/// For meshes that do not come from a local file (a download, an archive member, a
/// database blob) and for fuzzing the readers.
///
/// # Errors
/// [`Error::Malformed`] and [`Error::Unsupported`] as [`read_mesh_as`], naming `name`.
///
/// # Example
/// ```
/// use std::path::Path;
/// use tinsmith_formats::{read_mesh_bytes, MeshFormat};
/// # fn main() -> tinsmith_formats::Result<()> {
/// let obj = b"v 0 0 1\nv 1 0 2\nv 0 1 3\nf 1 2 3\n";
/// let mesh = read_mesh_bytes(Path::new("upload.obj"), obj, MeshFormat::Obj)?;
/// assert_eq!(mesh.triangles, [[0, 1, 2]]);
/// # Ok(())
/// # }
/// ```
pub fn read_mesh_bytes(name: &Path, bytes: &[u8], format: MeshFormat) -> Result<Mesh> {
    read_from(bytes, Some(bytes.len() as u64), format).map_err(|problem| problem.at(name, format))
}

/// Reads a mesh of `format` from `reader`, whose content is `len` bytes long when known.
fn read_from<R: BufRead>(
    reader: R,
    len: Option<u64>,
    format: MeshFormat,
) -> std::result::Result<Mesh, Problem> {
    match format {
        MeshFormat::Ply => ply::read(reader, len),
        MeshFormat::Obj => obj::read(reader),
        MeshFormat::Stl => stl::read(reader, len),
        MeshFormat::Glb => glb::read(reader, len),
        MeshFormat::GeoJson => geojson::read(reader),
        MeshFormat::FlatGeobuf => fgb::read(reader),
        MeshFormat::LandXml => landxml::read(reader),
    }
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
    /// Values float32 can hold relative to an origin.
    const MODERATE: [[f64; 3]; 4] = [
        [500_000.0, 4_649_776.25, 312.5],
        [0.1 + 0.2 + 500_000.0, 4_649_776.1, 1.0 / 3.0],
        [512_345.678_9, 4_653_456.789_012_3, 2_962.125],
        [501_000.0, 4_650_000.0, -0.0],
    ];
    const WKT: &str = "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\"],\
                       AUTHORITY[\"EPSG\",\"32633\"]]";

    #[test]
    fn round_trip_is_bit_exact_in_every_f64_format() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        for format in MeshFormat::ALL.into_iter().filter(|f| !f.is_float32()) {
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
    fn float32_formats_give_back_the_quantized_positions() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let vertices = &MODERATE;
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let origin = LocalOrigin::new([500_000.0, 4_649_776.0, 312.5]);
        let expected: Vec<[f64; 3]> = vertices.iter().map(|&p| origin.quantize(p)).collect();
        for format in [MeshFormat::Stl, MeshFormat::Glb] {
            let path = dir.path().join(format!("tile.{}", format.extension()));
            let mesh = MeshRef::new(vertices, &triangles).with_crs_wkt(WKT);
            let options = WriteOptions::new().with_origin(origin);
            write_mesh_with(&path, format, mesh, &options)?;
            let back = read_mesh(&path)?;
            assert_eq!(bits(&back.vertices), bits(&expected), "{format}");
            assert_eq!(back.triangles, triangles, "{format}");
            assert_eq!(back.crs_wkt.as_deref(), Some(WKT), "{format}");
            assert_eq!(
                std::fs::read_to_string(prj_path(&path)).ok().as_deref(),
                Some(WKT)
            );
            let again = dir.path().join(format!("again.{}", format.extension()));
            write_mesh_with(&again, format, back.as_mesh_ref(), &options)?;
            assert_eq!(
                std::fs::read(&path).ok(),
                std::fs::read(&again).ok(),
                "{format}"
            );
        }
        Ok(())
    }

    #[test]
    fn float32_formats_refuse_what_float32_cannot_hold() {
        let dir = tempfile::tempdir().expect("temp dir");
        for format in [MeshFormat::Stl, MeshFormat::Glb] {
            let path = dir.path().join(format!("tile.{}", format.extension()));
            let result = write_mesh(&path, format, MeshRef::new(&VERTICES, &TRIANGLES));
            assert!(
                matches!(result, Err(Error::BadOption { .. })),
                "{format}: {result:?}"
            );
        }
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn stl_base_must_be_below_every_vertex() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("solid.stl");
        let vertices = [[0.0, 0.0, 10.0], [1.0, 0.0, 11.0], [0.0, 1.0, 12.0]];
        let mesh = MeshRef::new(&vertices, &[[0, 1, 2]]);
        for base in [10.0, 10.000_000_000_1, f64::NAN] {
            let options = WriteOptions::new().with_base(base);
            let result = write_mesh_with(&path, MeshFormat::Stl, mesh, &options);
            let message = result.err().map(|e| e.to_string()).unwrap_or_default();
            assert!(message.contains("STL base"), "{base}: {message}");
        }
        assert!(entries(dir.path()).is_empty());
        write_mesh_with(
            &path,
            MeshFormat::Stl,
            mesh,
            &WriteOptions::new().with_base(0.0),
        )?;
        assert_eq!(read_mesh(&path)?.triangles, vec![[0, 1, 2]]);
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
                MeshRef::new(&MODERATE, &[]).with_crs_wkt(wkt),
            )?;
            let back = read_mesh(&path)?;
            assert_eq!(
                back.crs_wkt.as_deref(),
                Some("GEOGCS[\"WGS 84\",     DATUM[\"WGS_1984\"],     UNIT[\"degree\",0.01]]"),
                "{format}"
            );
            std::fs::remove_file(prj_path(&path)).ok();
            write_mesh(&path, format, MeshRef::new(&MODERATE, &[]))?;
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

        let unknown = dir.path().join("tile.dxf");
        std::fs::write(&unknown, b"0\nSECTION").expect("seed");
        let error = read_mesh(&unknown).expect_err("unknown extension");
        assert!(matches!(error, Error::UnknownExtension { .. }), "{error:?}");
        assert!(error.to_string().contains("tile.dxf"));

        let empty = dir.path().join("empty.obj");
        std::fs::write(&empty, b"").expect("seed");
        let error = read_mesh(&empty).expect_err("empty file");
        assert_eq!(
            error.to_string(),
            format!("{}: invalid OBJ file: the file is empty", empty.display())
        );
    }

    #[test]
    fn bytes_read_as_the_file_and_errors_name_the_given_name() -> Result<()> {
        let dir = tempfile::tempdir().expect("temp dir");
        for format in MeshFormat::ALL {
            let path = dir.path().join(format!("tile.{}", format.extension()));
            write_mesh(
                &path,
                format,
                MeshRef::new(&MODERATE, &[[0, 1, 2], [1, 3, 2]]),
            )?;
            let bytes = std::fs::read(&path).expect("read back");
            let from_bytes = read_mesh_bytes(Path::new("blob"), &bytes, format)?;
            let from_file = read_mesh(&path)?;
            assert_eq!(
                bits(&from_bytes.vertices),
                bits(&from_file.vertices),
                "{format}"
            );
            assert_eq!(from_bytes.triangles, from_file.triangles, "{format}");
            let error = read_mesh_bytes(Path::new("blob"), b"", format).expect_err("empty");
            assert!(error.to_string().starts_with("blob: "), "{format}: {error}");
        }
        Ok(())
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
