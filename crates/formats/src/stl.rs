//! Binary STL: float32 facets relative to a local origin kept in the 80-byte header, and
//! the optional base that closes the surface into a solid.
//!
//! A binary STL file is an 80-byte header, a `u32` facet count and 50 bytes per facet
//! (normal and three corners as little-endian `f32`, then a `u16` attribute). STL has no
//! place for an origin, so the header holds it as text: `tinsmith origin X Y Z`, followed by
//! ` base B` when the file was closed into a solid. A file whose header does not start with
//! `tinsmith origin` is read with the origin at zero.

use std::io::{self, Read, Write};

use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};
use crate::origin::LocalOrigin;
use crate::weld::Welder;

/// Header size in bytes.
pub(crate) const HEADER_LEN: usize = 80;
/// Bytes per facet.
const FACET_LEN: usize = 50;
/// What the header text starts with.
const MAGIC: &str = "tinsmith origin";

/// The facet count when closing `mesh` into a solid: top, two per boundary edge, bottom.
pub(crate) fn solid_facet_count(triangles: &[[u32; 3]]) -> u64 {
    2 * triangles.len() as u64 + 2 * boundary_edges(triangles).len() as u64
}

/// The header text for `origin` and `base`, or `None` when it does not fit in 80 bytes.
pub(crate) fn header_text(origin: LocalOrigin, base: Option<f64>) -> Option<String> {
    let [x, y, z] = origin.offset();
    let mut text = format!("{MAGIC} {x:?} {y:?} {z:?}");
    if let Some(base) = base {
        text.push_str(&format!(" base {base:?}"));
    }
    (text.len() <= HEADER_LEN).then_some(text)
}

/// The directed edges `(a, b)` used by exactly one triangle, in the direction that
/// triangle runs them, sorted by their vertices.
pub(crate) fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    let mut edges: Vec<((u32, u32), (u32, u32))> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| ((a.min(b), a.max(b)), (a, b)))
        .collect();
    edges.sort_unstable();
    let mut boundary = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        if j - i == 1 {
            boundary.push(edges[i].1);
        }
        i = j;
    }
    boundary
}

/// Writes `mesh` relative to `origin`; with `base`, adds the walls under every boundary
/// edge and the mirrored bottom. The caller has checked the mesh, that the facet count
/// fits a `u32`, that `header_text` fits, and that `base` is below every vertex after
/// float32 rounding.
pub(crate) fn write<W: Write>(
    mut w: W,
    mesh: MeshRef<'_>,
    origin: LocalOrigin,
    base: Option<f64>,
) -> io::Result<()> {
    let text = header_text(origin, base).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "origin too long for the header",
        )
    })?;
    let mut header = [b' '; HEADER_LEN];
    header[..text.len()].copy_from_slice(text.as_bytes());
    w.write_all(&header)?;

    let local = |i: u32| origin.to_local(mesh.vertices[i as usize]);
    let boundary = match base {
        Some(_) => boundary_edges(mesh.triangles),
        None => Vec::new(),
    };
    let count = match base {
        Some(_) => 2 * mesh.triangles.len() as u64 + 2 * boundary.len() as u64,
        None => mesh.triangles.len() as u64,
    };
    let count = u32::try_from(count)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many facets for STL"))?;
    w.write_all(&count.to_le_bytes())?;

    for &[a, b, c] in mesh.triangles {
        write_facet(&mut w, [local(a), local(b), local(c)])?;
    }
    if let Some(base) = base {
        let bz = origin.to_local([0.0, 0.0, base])[2];
        let down = |p: [f32; 3]| [p[0], p[1], bz];
        for &(a, b) in &boundary {
            // The top runs a -> b; the wall runs b -> a along the top so that every edge
            // is used once in each direction.
            let (pa, pb) = (local(a), local(b));
            write_facet(&mut w, [pb, pa, down(pa)])?;
            write_facet(&mut w, [pb, down(pa), down(pb)])?;
        }
        for &[a, b, c] in mesh.triangles {
            write_facet(&mut w, [down(local(a)), down(local(c)), down(local(b))])?;
        }
    }
    Ok(())
}

/// One facet: the unit normal of the float32 corners (zero if degenerate), the corners, a
/// zero attribute.
fn write_facet<W: Write>(w: &mut W, corners: [[f32; 3]; 3]) -> io::Result<()> {
    let p = corners.map(|c| c.map(f64::from));
    let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let normal = if length > 0.0 {
        n.map(|c| (c / length) as f32)
    } else {
        [0.0; 3]
    };
    let mut record = [0u8; FACET_LEN];
    for (i, value) in normal.iter().chain(corners.iter().flatten()).enumerate() {
        record[4 * i..4 * i + 4].copy_from_slice(&value.to_le_bytes());
    }
    w.write_all(&record)
}

/// The origin and base from a header, if it is one of ours.
fn parse_header(header: &[u8]) -> Result<(LocalOrigin, Option<f32>, Option<f64>), Problem> {
    let Some(rest) = header.strip_prefix(MAGIC.as_bytes()) else {
        return Ok((LocalOrigin::new([0.0; 3]), None, None));
    };
    let text = std::str::from_utf8(rest)
        .map_err(|_| Problem::malformed("the tinsmith header is not text"))?
        .trim_end_matches(['\0', ' ']);
    let bad = || Problem::malformed(format_args!("bad tinsmith header `{MAGIC}{text}`"));
    let mut tokens = text.split_ascii_whitespace();
    let mut offset = [0.0; 3];
    for c in &mut offset {
        *c = tokens
            .next()
            .and_then(|t| t.parse::<f64>().ok())
            .filter(|c| c.is_finite())
            .ok_or_else(bad)?;
    }
    let origin = LocalOrigin::new(offset);
    let base = match tokens.next() {
        None => None,
        Some("base") => Some(
            tokens
                .next()
                .and_then(|t| t.parse::<f64>().ok())
                .filter(|c| c.is_finite())
                .ok_or_else(bad)?,
        ),
        Some(_) => return Err(bad()),
    };
    if tokens.next().is_some() {
        return Err(bad());
    }
    let local_base = base.map(|b| origin.to_local([0.0, 0.0, b])[2]);
    Ok((origin, local_base, base))
}

/// Reads a binary STL file: corners welded into shared vertices by exact position, in the
/// file's facet order. Facets with a corner at the header's base height (the walls and
/// bottom of a closed solid) are skipped, so a solid reads back as its top surface.
pub(crate) fn read<R: Read>(mut r: R, file_len: Option<u64>) -> Result<Mesh, Problem> {
    let mut header = [0u8; HEADER_LEN + 4];
    let mut filled = 0;
    while filled < header.len() {
        let n = r.read(&mut header[filled..])?;
        if n == 0 {
            break;
        }
        filled += n;
    }
    if filled == 0 {
        return Err(Problem::malformed("the file is empty"));
    }
    if header[..filled].starts_with(b"solid")
        && file_len.is_none_or(|len| len < (HEADER_LEN + 4) as u64)
    {
        return Err(Problem::unsupported("ASCII STL; only binary STL is read"));
    }
    if filled < header.len() {
        return Err(Problem::malformed(format_args!(
            "{filled} bytes is shorter than the 84-byte binary STL header"
        )));
    }
    let count = u32::from_le_bytes([header[80], header[81], header[82], header[83]]);
    let expected = (HEADER_LEN as u64 + 4) + FACET_LEN as u64 * u64::from(count);
    if let Some(len) = file_len {
        if len != expected {
            if header.starts_with(b"solid") {
                return Err(Problem::unsupported("ASCII STL; only binary STL is read"));
            }
            return Err(Problem::malformed(format_args!(
                "the header announces {count} facets ({expected} bytes), but the file has \
                 {len} bytes (truncated or not a binary STL)"
            )));
        }
    }
    let (origin, local_base, _) = parse_header(&header[..HEADER_LEN])?;

    let mut welder = Welder::default();
    let mut triangles = Vec::new();
    let mut record = [0u8; FACET_LEN];
    for facet in 0..count {
        r.read_exact(&mut record)?;
        let mut corners = [[0f32; 3]; 3];
        for (i, value) in corners.iter_mut().flatten().enumerate() {
            let at = 12 + 4 * i;
            *value =
                f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]]);
            if !value.is_finite() {
                return Err(Problem::malformed(format_args!(
                    "facet {facet} has a non-finite coordinate"
                )));
            }
        }
        if local_base.is_some_and(|b| corners.iter().any(|c| c[2] == b)) {
            continue;
        }
        let mut triangle = [0u32; 3];
        for (index, corner) in triangle.iter_mut().zip(corners) {
            *index = welder
                .vertex(origin.to_world(corner))
                .ok_or_else(|| Problem::unsupported("more than 2^32 vertices"))?;
        }
        triangles.push(triangle);
    }
    Ok(Mesh::new(welder.into_vertices(), triangles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn write_to_vec(mesh: MeshRef<'_>, origin: LocalOrigin, base: Option<f64>) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh, origin, base).expect("writing to a Vec");
        bytes
    }

    /// A 3x3 vertex square with its centre cell missing... of a 2x2 grid of cells: an
    /// L-shaped domain of three cells, plus a separate triangle (two components).
    fn l_shape() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                vertices.push([
                    500_000.0 + x as f64,
                    5_000_000.0 + y as f64,
                    100.0 + x as f64,
                ]);
            }
        }
        vertices.extend([
            [500_010.0, 5_000_000.0, 90.0],
            [500_011.0, 5_000_000.0, 91.0],
        ]);
        vertices.push([500_010.0, 5_000_001.0, 92.0]);
        let v = |x: u32, y: u32| y * 3 + x;
        let mut triangles = Vec::new();
        for (x, y) in [(0, 0), (1, 0), (0, 1)] {
            triangles.push([v(x, y), v(x + 1, y), v(x + 1, y + 1)]);
            triangles.push([v(x, y), v(x + 1, y + 1), v(x, y + 1)]);
        }
        triangles.push([9, 10, 11]);
        (vertices, triangles)
    }

    /// Each triangle as its three corner positions.
    fn corner_positions(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[[f64; 3]; 3]> {
        triangles
            .iter()
            .map(|t| t.map(|i| vertices[i as usize]))
            .collect()
    }

    #[test]
    fn round_trip_gives_the_quantized_positions() -> Result<(), Problem> {
        let (vertices, triangles) = l_shape();
        let origin = LocalOrigin::of_points(&vertices);
        let bytes = write_to_vec(MeshRef::new(&vertices, &triangles), origin, None);
        assert_eq!(bytes.len(), 84 + 50 * triangles.len());
        assert!(bytes.starts_with(b"tinsmith origin 500005.5 5000001.0 96.0"));
        let mesh = read(bytes.as_slice(), Some(bytes.len() as u64))?;
        let expected: Vec<[f64; 3]> = vertices.iter().map(|&p| origin.quantize(p)).collect();
        assert_eq!(
            corner_positions(&mesh.vertices, &mesh.triangles),
            corner_positions(&expected, &triangles)
        );
        // Vertex (2, 2) of the 3x3 block is used by no triangle.
        assert_eq!(mesh.vertices.len(), vertices.len() - 1);
        Ok(())
    }

    #[test]
    fn boundary_edges_of_the_l_shape() {
        let (_, triangles) = l_shape();
        // 8 unit edges around the L, 3 around the lone triangle.
        assert_eq!(boundary_edges(&triangles).len(), 11);
    }

    #[test]
    fn base_closes_a_watertight_consistently_oriented_solid() -> Result<(), Problem> {
        let (vertices, triangles) = l_shape();
        let origin = LocalOrigin::of_points(&vertices);
        let bytes = write_to_vec(MeshRef::new(&vertices, &triangles), origin, Some(0.0));
        let count = solid_facet_count(&triangles);
        assert_eq!(bytes.len() as u64, 84 + 50 * count);
        // Every directed edge appears exactly once and its reverse exactly once.
        let mut directed: HashMap<([u32; 3], [u32; 3]), usize> = HashMap::new();
        for facet in bytes[84..].chunks_exact(50) {
            let corner = |k: usize| -> [u32; 3] {
                [0, 1, 2].map(|i| {
                    let at = 12 + 12 * k + 4 * i;
                    u32::from_le_bytes([facet[at], facet[at + 1], facet[at + 2], facet[at + 3]])
                })
            };
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                *directed.entry((corner(a), corner(b))).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge used twice in one direction");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge without its twin");
        }
        // Reading back skips the walls and the bottom.
        let mesh = read(bytes.as_slice(), Some(bytes.len() as u64))?;
        let expected: Vec<[f64; 3]> = vertices.iter().map(|&p| origin.quantize(p)).collect();
        assert_eq!(
            corner_positions(&mesh.vertices, &mesh.triangles),
            corner_positions(&expected, &triangles)
        );
        Ok(())
    }

    #[test]
    fn foreign_and_broken_files() {
        let mut foreign = vec![0u8; 84];
        foreign[..5].copy_from_slice(b"hello");
        let mesh = read(foreign.as_slice(), Some(84)).expect("an empty foreign STL");
        assert!(mesh.triangles.is_empty());

        let ascii = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n".to_vec();
        assert!(matches!(
            read(ascii.as_slice(), Some(ascii.len() as u64)),
            Err(Problem::Unsupported(_))
        ));
        let mut truncated = foreign.clone();
        truncated[80] = 2;
        truncated.extend([0u8; 60]);
        match read(truncated.as_slice(), Some(truncated.len() as u64)) {
            Err(Problem::Malformed(reason)) => assert!(reason.contains("truncated"), "{reason}"),
            other => panic!("{other:?}"),
        }
        let mut bad_header = vec![b' '; 84];
        bad_header[..20].copy_from_slice(b"tinsmith origin 1 x ");
        bad_header[80..].copy_from_slice(&[0; 4]);
        assert!(matches!(
            read(bad_header.as_slice(), Some(84)),
            Err(Problem::Malformed(_))
        ));
        assert!(matches!(
            read(&b""[..], Some(0)),
            Err(Problem::Malformed(_))
        ));
    }

    #[test]
    fn header_text_fits_or_is_refused() {
        let origin = LocalOrigin::new([1.0, 2.0, 3.0]);
        assert_eq!(
            header_text(origin, Some(-10.5)).as_deref(),
            Some("tinsmith origin 1.0 2.0 3.0 base -10.5")
        );
        let long = LocalOrigin::new([-1.234_567_890_123_456_7e-300; 3]);
        assert_eq!(header_text(long, None), None);
    }
}
