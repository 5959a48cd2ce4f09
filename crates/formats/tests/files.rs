//! Reads the fixture files through the public API: hand-written valid files must parse,
//! every file in `tests/malformed/` must give an error that names it, without panicking.

use std::path::{Path, PathBuf};

use tinsmith_formats::{read_mesh, write_mesh, Error, LocalOrigin, MeshFormat, MeshRef};

fn fixture(dir: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(dir)
        .join(name)
}

/// Each malformed fixture and a piece of the message it must produce.
const MALFORMED: &[(&str, &str)] = &[
    ("ascii_short_record.ply", "fewer values"),
    ("ascii_trailing_record.ply", "data after the last record"),
    ("ascii_truncated.ply", "truncated"),
    ("bad_number.obj", "`O` is not a number"),
    ("binary_noise.obj", "not text"),
    ("binary_noise.ply", "header line 2 is not text"),
    ("binary_trailing_bytes.ply", "data after the last record"),
    ("empty.obj", "the file is empty"),
    ("empty.ply", "the file is empty"),
    ("garbage.obj", "unknown statement `this`"),
    ("garbage.ply", "does not start with `ply`"),
    ("header_only.ply", "truncated"),
    ("huge_count.ply", "truncated"),
    ("huge_feature.fgb", "truncated"),
    ("index_out_of_range.obj", "out of range"),
    ("index_out_of_range.ply", "out of range"),
    ("nan_vertex.ply", "non-finite"),
    ("negative_index.ply", "out of range"),
    ("negative_out_of_range.obj", "out of range"),
    ("no_end_header.ply", "end_header"),
    ("quad_face.obj", "only triangles"),
    ("quad_face.ply", "only triangles"),
    ("short_property.fgb", "properties end inside a value"),
    ("short_vertex.obj", "3 coordinates"),
    ("truncated_faces.ply", "truncated"),
    ("truncated_vertices.ply", "truncated"),
    ("unknown_type.ply", "unknown property type"),
    ("zero_index.obj", "index 0"),
];

#[test]
fn every_malformed_fixture_fails_naming_the_file() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .expect("tests/malformed exists")
        .map(|entry| {
            entry
                .expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    on_disk.sort();
    let listed: Vec<String> = MALFORMED
        .iter()
        .map(|(name, _)| (*name).to_owned())
        .collect();
    assert_eq!(
        on_disk, listed,
        "every fixture needs an expected message, and vice versa"
    );

    for (name, expected) in MALFORMED {
        let path = fixture("malformed", name);
        let error = match read_mesh(&path) {
            Ok(mesh) => panic!("{name}: expected an error, read {mesh:?}"),
            Err(error) => error,
        };
        assert!(
            matches!(error, Error::Malformed { .. } | Error::Unsupported { .. }),
            "{name}: {error:?}"
        );
        let message = error.to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{name}: {message}"
        );
        assert!(
            message.contains(expected),
            "{name}: {expected:?} not in {message:?}"
        );
    }
}

#[test]
fn quads_are_reported_as_unsupported() {
    for name in ["quad_face.ply", "quad_face.obj"] {
        let error = read_mesh(&fixture("malformed", name)).err();
        assert!(
            matches!(error, Some(Error::Unsupported { .. })),
            "{name}: {error:?}"
        );
    }
}

#[test]
fn hand_written_ascii_ply_parses() -> tinsmith_formats::Result<()> {
    let mesh = read_mesh(&fixture("data", "hand_ascii.ply"))?;
    assert_eq!(
        mesh.vertices,
        vec![
            [500_000.0, 5_600_000.0, 100.5],
            [500_010.0, 5_600_000.0, 101.25],
            [500_010.0, 5_600_010.0, 99.75],
            [500_000.0, 5_600_010.0, 100.0],
        ]
    );
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(mesh.crs_wkt.as_deref(), Some("EPSG:25832"));
    Ok(())
}

#[test]
fn obj_with_texture_normal_forms_and_negative_indices_parses() -> tinsmith_formats::Result<()> {
    let mesh = read_mesh(&fixture("data", "slashes_and_negatives.obj"))?;
    assert_eq!(mesh.vertices.len(), 4);
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(mesh.crs_wkt.as_deref(), Some("EPSG:25832"));
    Ok(())
}

#[test]
fn fixtures_convert_between_formats_unchanged() -> tinsmith_formats::Result<()> {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut original = read_mesh(&fixture("data", "hand_ascii.ply"))?;
    // Its extra vertex property is read as an attribute, which the conversion (positions,
    // triangles, CRS) does not carry.
    assert_eq!(
        original.attribute("intensity"),
        Some(&[12.0, 13.0, 14.0, 15.0][..])
    );
    original.attributes.clear();
    let mut current = original.clone();
    for format in [MeshFormat::Obj, MeshFormat::Ply, MeshFormat::Obj] {
        let path = dir.path().join(format!("converted.{}", format.extension()));
        write_mesh(&path, format, current.as_mesh_ref())?;
        current = read_mesh(&path)?;
        assert_eq!(current, original, "{format}");
    }
    Ok(())
}

#[test]
fn a_large_mesh_round_trips_in_every_format() -> tinsmith_formats::Result<()> {
    // A 300 x 300 grid in UTM coordinates with irregular heights.
    let n = 300u32;
    let vertices: Vec<[f64; 3]> = (0..n * n)
        .map(|i| {
            let (col, row) = (f64::from(i % n), f64::from(i / n));
            let height = (col * 0.37).sin() * 120.0 + (row * 0.11).cos() * 35.0 + 1_000.0 / 3.0;
            [500_000.0 + col * 0.5, 5_600_000.0 - row * 0.5, height]
        })
        .collect();
    let mut triangles = Vec::new();
    for row in 0..n - 1 {
        for col in 0..n - 1 {
            let i = row * n + col;
            triangles.push([i, i + n, i + 1]);
            triangles.push([i + 1, i + n, i + n + 1]);
        }
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let origin = LocalOrigin::of_points(&vertices);
    let corners = |vertices: &[[f64; 3]], triangles: &[[u32; 3]]| -> Vec<u64> {
        triangles
            .iter()
            .flatten()
            .flat_map(|&i| vertices[i as usize])
            .map(f64::to_bits)
            .collect()
    };
    for format in MeshFormat::ALL {
        let path = dir.path().join(format!("grid.{}", format.extension()));
        write_mesh(&path, format, MeshRef::new(&vertices, &triangles))?;
        let mesh = read_mesh(&path)?;
        // Float32 formats give back the positions relative to the default origin.
        let expected: Vec<[f64; 3]> = if format.is_float32() {
            vertices.iter().map(|&p| origin.quantize(p)).collect()
        } else {
            vertices.clone()
        };
        assert_eq!(mesh.vertices.len(), vertices.len(), "{format}");
        assert_eq!(mesh.triangles.len(), triangles.len(), "{format}");
        assert!(
            corners(&mesh.vertices, &mesh.triangles) == corners(&expected, &triangles),
            "{format}"
        );
        if matches!(
            format,
            MeshFormat::Ply | MeshFormat::Obj | MeshFormat::Glb | MeshFormat::LandXml
        ) {
            // Indexed formats keep the vertex order too.
            assert_eq!(mesh.triangles, triangles, "{format}");
        }
    }
    Ok(())
}
