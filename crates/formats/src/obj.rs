//! Wavefront OBJ: `v` and `f` lines, read and written.
//!
//! Only the geometry statements matter here: `v x y z` (optionally followed by `w` or a
//! colour) and `f a b c` with 1-based or negative (relative) indices in the forms `a`,
//! `a/t`, `a/t/n` and `a//n`. Other statements of the OBJ specification (`vt`, `vn`, `g`,
//! `usemtl`, …) are skipped; anything else is an error.

use std::io::{self, BufRead, Read, Write};

use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};

/// Longest line accepted; guards against reading a whole binary file as one line.
const MAX_LINE: u64 = 1 << 20;

/// Statements of the OBJ specification that carry nothing this crate reads.
const SKIPPED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "l",
    "p",
    "g",
    "o",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
    "maplib",
    "usemap",
];

/// Writes `mesh`: a `# tinsmith` line, `# crs: <wkt>` if there is a CRS, then one
/// `v x y z` line per vertex and one 1-based `f a b c` line per triangle.
///
/// Coordinates are written with `f64`'s `Debug` format, the shortest text that parses back to
/// the same value (with an exponent for very small or large magnitudes, as `1e-300`).
pub(crate) fn write<W: Write>(mut w: W, mesh: MeshRef<'_>) -> io::Result<()> {
    w.write_all(b"# tinsmith\n")?;
    if let Some(crs) = mesh.crs_line() {
        writeln!(w, "# crs: {crs}")?;
    }
    for (i, [x, y, z]) in mesh.vertices.iter().enumerate() {
        match mesh.colours {
            // The common extension (MeshLab, trimesh): colour components in 0..1.
            Some(colours) => {
                let [r, g, b] = colours[i].map(|c| f64::from(c) / 255.0);
                writeln!(w, "v {x:?} {y:?} {z:?} {r:?} {g:?} {b:?}")?;
            }
            None => writeln!(w, "v {x:?} {y:?} {z:?}")?,
        }
    }
    for &[a, b, c] in mesh.triangles {
        writeln!(
            w,
            "f {} {} {}",
            u64::from(a) + 1,
            u64::from(b) + 1,
            u64::from(c) + 1
        )?;
    }
    Ok(())
}

/// Reads an OBJ file's vertices, triangles and `# crs:` comment.
pub(crate) fn read<R: BufRead>(mut r: R) -> Result<Mesh, Problem> {
    let mut buf = Vec::new();
    let mut line_number = 0u64;
    let mut mesh = Mesh::default();
    // The largest positive index seen and its line; checked at the end because the
    // specification does not forbid faces before their vertices.
    let mut largest: Option<(u64, u64)> = None;
    loop {
        buf.clear();
        let n = r.by_ref().take(MAX_LINE).read_until(b'\n', &mut buf)?;
        if n == 0 {
            break;
        }
        line_number += 1;
        let at = |what: std::fmt::Arguments<'_>| {
            Problem::malformed(format_args!("line {line_number}: {what}"))
        };
        if n as u64 == MAX_LINE && buf.last() != Some(&b'\n') {
            return Err(at(format_args!("longer than {MAX_LINE} bytes")));
        }
        let line = std::str::from_utf8(&buf)
            .map_err(|_| at(format_args!("not text")))?
            .trim();
        if let Some(comment) = line.strip_prefix('#') {
            if mesh.crs_wkt.is_none() {
                if let Some(crs) = comment.trim_start().strip_prefix("crs:") {
                    let crs = crs.trim();
                    if !crs.is_empty() {
                        mesh.crs_wkt = Some(crs.to_owned());
                    }
                }
            }
            continue;
        }
        let statement = line.split('#').next().unwrap_or_default();
        let mut tokens = statement.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut vertex = [0.0f64; 3];
                for (axis, coordinate) in vertex.iter_mut().enumerate() {
                    let token = tokens.next().ok_or_else(|| {
                        at(format_args!("a vertex needs 3 coordinates, found {axis}"))
                    })?;
                    *coordinate = token
                        .parse::<f64>()
                        .map_err(|_| at(format_args!("`{token}` is not a number")))?;
                    if !coordinate.is_finite() {
                        return Err(at(format_args!("the vertex has a non-finite coordinate")));
                    }
                }
                // x y z, then w (1 value) or a colour (3 or 4 values).
                if tokens.count() > 4 {
                    return Err(at(format_args!("too many values for a vertex")));
                }
                mesh.vertices.push(vertex);
            }
            "f" => {
                let mut triangle = [0u32; 3];
                let mut corners = 0usize;
                for token in tokens {
                    if corners >= 3 {
                        corners += 1;
                        continue;
                    }
                    let mut parts = token.split('/');
                    let vertex = parts.next().unwrap_or_default();
                    if parts.count() > 2 {
                        return Err(at(format_args!("`{token}` is not a face vertex")));
                    }
                    let index = vertex
                        .parse::<i64>()
                        .map_err(|_| at(format_args!("`{token}` is not a vertex index")))?;
                    let zero_based = match index {
                        0 => return Err(at(format_args!("vertex index 0 (indices start at 1)"))),
                        1.. => {
                            let zero_based = index.unsigned_abs() - 1;
                            if largest.is_none_or(|(largest, _)| zero_based > largest) {
                                largest = Some((zero_based, line_number));
                            }
                            zero_based
                        }
                        _ => mesh
                            .vertices
                            .len()
                            .checked_sub(
                                usize::try_from(index.unsigned_abs()).unwrap_or(usize::MAX),
                            )
                            .map(|i| i as u64)
                            .ok_or_else(|| {
                                at(format_args!(
                                    "relative index {index} refers to no vertex: only {} are \
                                     defined before it (index out of range)",
                                    mesh.vertices.len()
                                ))
                            })?,
                    };
                    triangle[corners] = u32::try_from(zero_based)
                        .map_err(|_| at(format_args!("vertex index {index} is out of range")))?;
                    corners += 1;
                }
                if corners != 3 {
                    return Err(Problem::unsupported(format_args!(
                        "line {line_number}: a face with {corners} vertices; only triangles (3 \
                         vertices) are supported"
                    )));
                }
                mesh.triangles.push(triangle);
            }
            _ if SKIPPED.contains(&keyword) => {}
            _ => return Err(at(format_args!("unknown statement `{keyword}`"))),
        }
    }
    if line_number == 0 {
        return Err(Problem::malformed("the file is empty"));
    }
    if let Some((index, line)) = largest {
        if index >= mesh.vertices.len() as u64 {
            return Err(Problem::malformed(format_args!(
                "line {line}: a face refers to vertex {}, but the file has {} vertices (index \
                 out of range)",
                index + 1,
                mesh.vertices.len()
            )));
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_to_string(mesh: MeshRef<'_>) -> String {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh).expect("writing to a Vec");
        String::from_utf8(bytes).expect("OBJ is text")
    }

    fn read_str(text: &str) -> Result<Mesh, Problem> {
        read(text.as_bytes())
    }

    fn reason(text: &[u8]) -> String {
        match read(text) {
            Ok(mesh) => panic!("expected an error, read {mesh:?}"),
            Err(Problem::Malformed(reason) | Problem::Unsupported(reason)) => reason,
            Err(Problem::Io(error)) => panic!("unexpected I/O error {error}"),
        }
    }

    #[test]
    fn output_is_exactly_as_documented() {
        let vertices = [
            [1.0, 2.5, -3.0],
            [1e-300, 5e6, -3.4e38],
            [0.1 + 0.2, 0.0, -0.0],
        ];
        let text =
            write_to_string(MeshRef::new(&vertices, &[[0, 1, 2]]).with_crs_wkt("EPSG:25832\n"));
        assert_eq!(
            text,
            "# tinsmith\n# crs: EPSG:25832\nv 1.0 2.5 -3.0\nv 1e-300 5000000.0 -3.4e38\n\
             v 0.30000000000000004 0.0 -0.0\nf 1 2 3\n"
        );
    }

    #[test]
    fn written_file_reads_back_bit_exactly() -> Result<(), Problem> {
        let vertices = [
            [1e-300, -0.0, 5e-324],
            [500_000.123_456_789, 4_649_776.987_654_321, -3.4e38],
            [0.1 + 0.2, f64::MAX, f64::MIN_POSITIVE],
            [std::f64::consts::PI, -1.0 / 3.0, 1e22],
        ];
        let triangles = [[0, 1, 2], [3, 2, 1]];
        let mesh = read_str(&write_to_string(
            MeshRef::new(&vertices, &triangles).with_crs_wkt("PROJCS[\"x\"]"),
        ))?;
        let bits =
            |v: &[[f64; 3]]| -> Vec<u64> { v.iter().flatten().map(|c| c.to_bits()).collect() };
        assert_eq!(bits(&mesh.vertices), bits(&vertices));
        assert_eq!(mesh.triangles, triangles);
        assert_eq!(mesh.crs_wkt.as_deref(), Some("PROJCS[\"x\"]"));
        Ok(())
    }

    #[test]
    fn face_vertex_forms_and_negative_indices_parse() -> Result<(), Problem> {
        let text = "# made by hand\r\nmtllib a.mtl\no tile\nv 0 0 0\nv 1 0 0 1.0\n\
            v 1 1 0 0.5 0.5 0.5\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng ground\nusemtl grass\ns off\n\
            f 1/1/1 2/2/2 3/3/3\nf 1//1 3//1 4//1 # trailing comment\nf 1/1 2/1 4/1\n\
            f -4 -3 -2\nv 5 5 5\nf -1 1 2\n\n";
        let mesh = read_str(text)?;
        assert_eq!(mesh.vertices.len(), 5);
        assert_eq!(mesh.vertices[4], [5.0, 5.0, 5.0]);
        assert_eq!(
            mesh.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 1, 3], [0, 1, 2], [4, 0, 1]]
        );
        assert_eq!(mesh.crs_wkt, None);
        Ok(())
    }

    #[test]
    fn faces_may_come_before_their_vertices() -> Result<(), Problem> {
        let mesh = read_str("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")?;
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        Ok(())
    }

    #[test]
    fn non_triangles_are_unsupported() {
        for face in ["f 1 2 3 4", "f 1 2", "f 1 2 3 1 2 3 1 2 3"] {
            let text = format!("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n{face}\n");
            match read_str(&text) {
                Err(Problem::Unsupported(message)) => {
                    let count = face.split_ascii_whitespace().count() - 1;
                    assert!(
                        message.contains(&format!("with {count} vertices")),
                        "{message}"
                    );
                    assert!(message.contains("only triangles"), "{message}");
                    assert!(message.contains("line 5"), "{message}");
                }
                other => panic!("{face}: {other:?}"),
            }
        }
    }

    #[test]
    fn bad_indices_are_reported() {
        let vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let cases = [
            ("f 1 2 4\n", "out of range"),
            ("f -4 1 2\n", "out of range"),
            ("f 0 1 2\n", "index 0"),
            ("f 1 2 99999999999\n", "out of range"),
            ("f 1 2 x\n", "not a vertex index"),
            ("f 1 2 /3\n", "not a vertex index"),
            ("f 1 2 3/1/1/1\n", "not a face vertex"),
        ];
        for (face, expected) in cases {
            let message = reason(format!("{vertices}{face}").as_bytes());
            assert!(message.contains(expected), "{face}: {message}");
            assert!(message.contains("line 4"), "{face}: {message}");
        }
    }

    #[test]
    fn bad_text_is_reported() {
        let cases: [(&[u8], &str); 7] = [
            (b"", "empty"),
            (b"hello world\n", "unknown statement `hello`"),
            (b"v 1 2\n", "3 coordinates"),
            (b"v 1 2 three\n", "`three` is not a number"),
            (b"v 1 2 nan\n", "non-finite"),
            (b"v 1 2 3 4 5 6 7 8\n", "too many"),
            (b"v 1 2 3\n\xff\xfe\x00\x01\n", "line 2: not text"),
        ];
        for (text, expected) in cases {
            let message = reason(text);
            assert!(
                message.contains(expected),
                "{expected:?} not in {message:?}"
            );
        }
        let garbage = vec![b'x'; 2 * MAX_LINE as usize];
        assert!(reason(&garbage).contains("longer than"));
    }

    #[test]
    fn empty_mesh_round_trips() -> Result<(), Problem> {
        let mesh = read_str(&write_to_string(MeshRef::new(&[], &[])))?;
        assert_eq!(mesh, Mesh::default());
        Ok(())
    }

    #[test]
    fn every_truncation_and_corruption_is_an_error_or_a_mesh_never_a_panic() {
        let file = b"# crs: X\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 -2//1 3\n".to_vec();
        for cut in 0..file.len() {
            let _ = read(&file[..cut]);
        }
        for position in 0..file.len() {
            for value in [0x00, 0xFF, b'\n', b' ', b'/', b'-', b'0', b'9', b'#'] {
                let mut corrupt = file.clone();
                corrupt[position] = value;
                if let Ok(mesh) = read(corrupt.as_slice()) {
                    let count = mesh.vertices.len();
                    assert!(mesh
                        .triangles
                        .iter()
                        .flatten()
                        .all(|&i| (i as usize) < count));
                }
            }
        }
    }
}
