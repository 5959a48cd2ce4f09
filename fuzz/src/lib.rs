//! What the fuzz targets share: the checks a reader's answer must pass.

use std::path::Path;

use tinsmith_formats::{read_mesh_bytes, Error, MeshFormat};

/// The name the readers are given for the fuzz input; every error must start with it.
pub const NAME: &str = "fuzz-input";

/// Reads `data` as a mesh of `format` and checks the answer: an error names the input and
/// is one a malformed file gives; a mesh has finite coordinates and in-range indices.
/// Panics (a finding) otherwise.
pub fn read_mesh(data: &[u8], format: MeshFormat) {
    match read_mesh_bytes(Path::new(NAME), data, format) {
        Ok(mesh) => {
            for (i, v) in mesh.vertices.iter().enumerate() {
                assert!(v.iter().all(|c| c.is_finite()), "vertex {i} is {v:?}");
            }
            let n = mesh.vertices.len();
            for (i, t) in mesh.triangles.iter().enumerate() {
                assert!(
                    t.iter().all(|&k| (k as usize) < n),
                    "triangle {i} is {t:?} of {n}"
                );
            }
        }
        Err(error) => {
            let message = error.to_string();
            assert!(message.starts_with(NAME), "{message}");
            assert!(
                matches!(error, Error::Malformed { .. } | Error::Unsupported { .. }),
                "{error:?}"
            );
        }
    }
}
