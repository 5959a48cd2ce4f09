//! glTF 2.0 binary (`.glb`): one node whose translation is the local origin, one indexed
//! triangle primitive with float32 positions (and optionally normals) relative to it.
//!
//! glTF is Y-up and right-handed; tinsmith's world is (x east, y north, z up). The writer
//! maps world `(x, y, z)` to glTF `(x, z, -y)`, a proper rotation (−90° about x) that keeps
//! triangles counter-clockwise seen from above as glTF front faces. Both the node
//! translation (f64, in the JSON) and the positions (f32) are in glTF axes, so a glTF
//! viewer shows the terrain right side up in its true position, and the reader maps back:
//! world `x = tx + px`, `y = -(tz + pz)`, `z = ty + py` — exactly
//! [`LocalOrigin::quantize`] of the written vertex.

use std::io::{self, Read, Write};

use serde_json::{json, Value};

use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};
use crate::origin::LocalOrigin;

/// `glTF` in ASCII, little-endian.
const MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk.
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk.
const CHUNK_BIN: u32 = 0x004E_4942;
/// Component types.
const FLOAT: u64 = 5126;
const UNSIGNED_BYTE: u64 = 5121;
const UNSIGNED_SHORT: u64 = 5123;
const UNSIGNED_INT: u64 = 5125;
/// Largest JSON chunk read.
const MAX_JSON: u32 = 64 << 20;

/// World `(x, y, z)` offsets to glTF axes.
fn to_gltf(p: [f32; 3]) -> [f32; 3] {
    [p[0], p[2], -p[1]]
}

/// Rounds `n` up to a multiple of 4.
fn pad4(n: u64) -> u64 {
    n.div_ceil(4) * 4
}

/// Per-vertex unit normals in world axes: the area-weighted mean of the incident triangles'
/// normals, computed from the float32 positions; straight up for a vertex without area.
fn vertex_normals(local: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut sums = vec![[0.0f64; 3]; local.len()];
    for &[a, b, c] in triangles {
        let p = [a, b, c].map(|i| local[i as usize].map(f64::from));
        let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        // Twice the area times the unit normal.
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for i in [a, b, c] {
            for (sum, component) in sums[i as usize].iter_mut().zip(n) {
                *sum += component;
            }
        }
    }
    sums.into_iter()
        .map(|n| {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if length > 0.0 && length.is_finite() {
                n.map(|c| (c / length) as f32)
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

/// Writes a GLB's 12-byte header and its JSON chunk (`json`, padded with spaces to a
/// multiple of 4 bytes) and, with `bin_len`, the binary chunk's 8-byte header: the caller
/// writes those `bin_len` bytes (a multiple of 4) next. The container every GLB tinsmith
/// writes starts with (meshes here, terrain tiles in `tinsmith-terrain`).
///
/// # Errors
/// The writer's, and `InvalidInput` for a file of 4 GiB or more.
pub fn write_glb_start<W: Write>(w: &mut W, json: &[u8], bin_len: Option<u64>) -> io::Result<()> {
    let padded = json.len().next_multiple_of(4);
    let length = 12 + 8 + padded as u64 + bin_len.map_or(0, |n| 8 + n);
    let (Ok(length), Ok(bin)) = (u32::try_from(length), u32::try_from(bin_len.unwrap_or(0))) else {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "larger than 4 GiB",
        ));
    };
    w.write_all(&MAGIC.to_le_bytes())?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&length.to_le_bytes())?;
    w.write_all(&(padded as u32).to_le_bytes())?;
    w.write_all(&CHUNK_JSON.to_le_bytes())?;
    w.write_all(json)?;
    w.write_all(&b"   "[..padded - json.len()])?;
    if bin_len.is_some() {
        w.write_all(&bin.to_le_bytes())?;
        w.write_all(&CHUNK_BIN.to_le_bytes())?;
    }
    Ok(())
}

/// Writes `mesh` as GLB relative to `origin`, with normals if asked. The caller has
/// checked the mesh.
pub(crate) fn write<W: Write>(
    mut w: W,
    mesh: MeshRef<'_>,
    origin: LocalOrigin,
    normals: bool,
) -> io::Result<()> {
    let [ox, oy, oz] = origin.offset();
    let mut extras = json!({
        "generator": "tinsmith",
        "origin": [ox, oy, oz],
        "axes": "glTF (x, y, z) = file (x, z, -y): x east, y north, z up; with \
                 --pixel-coords x column, y row (south), z value, so mirrored north-south",
    });
    if let Some(crs) = mesh.crs_line() {
        extras["crs_wkt"] = Value::from(crs);
    }
    if let Some(epsg) = mesh.epsg {
        extras["epsg"] = Value::from(epsg);
    }
    let mut node = json!({
        "name": "tin",
        "translation": [ox, oz, -oy],
        "extras": extras,
    });
    let mut root = json!({
        "asset": { "version": "2.0", "generator": concat!("tinsmith ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
    });

    let has_mesh = !mesh.vertices.is_empty() && !mesh.triangles.is_empty();
    let vertex_count = mesh.vertices.len() as u64;
    // 65535 is the primitive restart value, which glTF forbids in indices.
    let small = vertex_count <= 65_535;
    let index_size: u64 = if small { 2 } else { 4 };
    let positions_len = 12 * vertex_count;
    let normals_len = if normals { positions_len } else { 0 };
    // Each vertex attribute: one float32 per vertex, after the normals.
    let attribute_len = 4 * vertex_count;
    let attributes_len = attribute_len * mesh.attributes.len() as u64
        + if mesh.colours.is_some() {
            12 * vertex_count
        } else {
            0
        };
    let indices_len = index_size * 3 * mesh.triangles.len() as u64;
    let total_len = pad4(positions_len + normals_len + attributes_len + indices_len);

    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    if has_mesh {
        for &p in mesh.vertices {
            let g = to_gltf(origin.to_local(p));
            for axis in 0..3 {
                min[axis] = min[axis].min(g[axis]);
                max[axis] = max[axis].max(g[axis]);
            }
        }
        // Exact f32 values, written as the f64 they convert to.
        let exact = |v: [f32; 3]| v.map(f64::from);
        let mut attributes = json!({ "POSITION": 0 });
        let mut accessors = vec![json!({
            "bufferView": 0, "componentType": FLOAT, "count": vertex_count, "type": "VEC3",
            "min": exact(min), "max": exact(max),
        })];
        let mut views = vec![json!({
            "buffer": 0, "byteOffset": 0, "byteLength": positions_len, "target": 34962,
        })];
        if normals {
            attributes["NORMAL"] = Value::from(1);
            accessors.push(json!({
                "bufferView": 1, "componentType": FLOAT, "count": vertex_count, "type": "VEC3",
            }));
            views.push(json!({
                "buffer": 0, "byteOffset": positions_len, "byteLength": normals_len,
                "target": 34962,
            }));
        }
        for (k, attribute) in mesh.attributes.iter().enumerate() {
            attributes[attribute_semantic(attribute.name)] = Value::from(accessors.len());
            accessors.push(json!({
                "bufferView": views.len(), "componentType": FLOAT, "count": vertex_count,
                "type": "SCALAR",
            }));
            views.push(json!({
                "buffer": 0, "byteOffset": positions_len + normals_len + k as u64 * attribute_len,
                "byteLength": attribute_len, "target": 34962,
            }));
        }
        if mesh.colours.is_some() {
            attributes["COLOR_0"] = Value::from(accessors.len());
            accessors.push(json!({
                "bufferView": views.len(), "componentType": FLOAT, "count": vertex_count,
                "type": "VEC3",
            }));
            views.push(json!({
                "buffer": 0,
                "byteOffset": positions_len + normals_len
                    + attribute_len * mesh.attributes.len() as u64,
                "byteLength": 12 * vertex_count, "target": 34962,
            }));
        }
        accessors.push(json!({
            "bufferView": views.len(),
            "componentType": if small { UNSIGNED_SHORT } else { UNSIGNED_INT },
            "count": 3 * mesh.triangles.len() as u64,
            "type": "SCALAR",
        }));
        views.push(json!({
            "buffer": 0, "byteOffset": positions_len + normals_len + attributes_len,
            "byteLength": indices_len,
            "target": 34963,
        }));
        node["mesh"] = Value::from(0);
        root["meshes"] = json!([{
            "name": "tin",
            "primitives": [{ "attributes": attributes, "indices": accessors.len() - 1, "mode": 4 }],
        }]);
        root["accessors"] = Value::from(accessors);
        root["bufferViews"] = Value::from(views);
        root["buffers"] = json!([{ "byteLength": total_len }]);
    }
    root["nodes"] = json!([node]);

    let json_bytes = serde_json::to_vec(&root).map_err(io::Error::other)?;
    write_glb_start(&mut w, &json_bytes, has_mesh.then_some(total_len))?;
    if !has_mesh {
        return Ok(());
    }
    let local: Vec<[f32; 3]> = if normals {
        mesh.vertices.iter().map(|&p| origin.to_local(p)).collect()
    } else {
        Vec::new()
    };
    for &p in mesh.vertices {
        for c in to_gltf(origin.to_local(p)) {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    if normals {
        for n in vertex_normals(&local, mesh.triangles) {
            for c in to_gltf(n) {
                w.write_all(&c.to_le_bytes())?;
            }
        }
    }
    for attribute in mesh.attributes {
        for &value in attribute.values {
            w.write_all(&(value as f32).to_le_bytes())?;
        }
    }
    for colour in mesh.colours.unwrap_or(&[]) {
        for c in colour {
            w.write_all(&(f32::from(*c) / 255.0).to_le_bytes())?;
        }
    }
    for &index in mesh.triangles.iter().flatten() {
        if small {
            w.write_all(&(index as u16).to_le_bytes())?;
        } else {
            w.write_all(&index.to_le_bytes())?;
        }
    }
    let written = positions_len + normals_len + attributes_len + indices_len;
    w.write_all(&vec![0u8; (total_len - written) as usize])?;
    Ok(())
}

/// The glTF attribute semantic of a vertex attribute: application-specific semantics
/// start with `_`; by convention in capitals (`band_2` is `_BAND_2`).
pub(crate) fn attribute_semantic(name: &str) -> String {
    format!("_{}", name.to_ascii_uppercase())
}

/// A little-endian `u32` at `at`.
fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Reads a GLB file: the meshes of the default scene's nodes (translations only, through
/// parent nodes; an identity rotation, scale or matrix is allowed), every triangle
/// primitive, positions mapped back to world axes through the translations. Vertices of
/// several primitives are concatenated.
pub(crate) fn read<R: Read>(mut r: R, file_len: Option<u64>) -> Result<Mesh, Problem> {
    let mut header = [0u8; 20];
    r.read_exact(&mut header).map_err(|error| match file_len {
        Some(0) => Problem::malformed("the file is empty"),
        _ => Problem::from(error),
    })?;
    if u32_at(&header, 0) != MAGIC {
        return Err(Problem::malformed(
            "does not start with `glTF` (not a GLB file)",
        ));
    }
    if u32_at(&header, 4) != 2 {
        return Err(Problem::unsupported(format_args!(
            "GLB version {}; only 2 is read",
            u32_at(&header, 4)
        )));
    }
    let length = u64::from(u32_at(&header, 8));
    match file_len {
        Some(len) if len < length => {
            return Err(Problem::malformed(format_args!(
                "the header announces {length} bytes, the file has fewer (truncated)"
            )))
        }
        // Bytes past the declared end are no part of the GLB: a file cut or joined wrong.
        Some(len) if len > length => {
            return Err(Problem::malformed(format_args!(
                "the header announces {length} bytes, the file has {len}"
            )))
        }
        _ => {}
    }
    let (json_len, json_type) = (u32_at(&header, 12), u32_at(&header, 16));
    if json_type != CHUNK_JSON || json_len > MAX_JSON || u64::from(json_len) + 20 > length {
        return Err(Problem::malformed(
            "the first chunk is not a valid JSON chunk",
        ));
    }
    let mut json_bytes = vec![0u8; json_len as usize];
    r.read_exact(&mut json_bytes)?;
    let root: Value = serde_json::from_slice(&json_bytes)
        .map_err(|e| Problem::malformed(format_args!("JSON chunk: {e}")))?;
    // glTF requires `asset.version`; its major version must be 2, as the header's is.
    match root["asset"]["version"].as_str() {
        Some(version) if version.split('.').next() == Some("2") => {}
        Some(version) => {
            return Err(Problem::unsupported(format_args!(
                "glTF asset version {version}; only 2.x is read"
            )))
        }
        None => {
            return Err(Problem::malformed(
                "the JSON has no asset.version (required by glTF)",
            ))
        }
    }

    let mut bin = Vec::new();
    let rest = length - 20 - u64::from(json_len);
    if rest >= 8 {
        let mut chunk = [0u8; 8];
        r.read_exact(&mut chunk)?;
        let (bin_len, bin_type) = (u64::from(u32_at(&chunk, 0)), u32_at(&chunk, 4));
        if bin_type != CHUNK_BIN || bin_len > rest - 8 {
            return Err(Problem::malformed(
                "the second chunk is not a valid BIN chunk",
            ));
        }
        bin = vec![0u8; bin_len as usize];
        r.read_exact(&mut bin)?;
    }
    Gltf {
        root: &root,
        bin: &bin,
    }
    .mesh()
}

/// The parsed JSON and the binary chunk.
struct Gltf<'a> {
    root: &'a Value,
    bin: &'a [u8],
}

/// A JSON member as an index or count.
fn usize_of(value: &Value, what: &str) -> Result<usize, Problem> {
    value
        .as_u64()
        .and_then(|v| usize::try_from(v).ok())
        .ok_or_else(|| Problem::malformed(format_args!("{what} is not a non-negative integer")))
}

/// Node `n`'s translation. A rotation, scale or matrix is refused unless it is the
/// identity (a matrix may translate): tinsmith meshes are placed by translation alone.
fn translation_of(node: &Value, n: usize) -> Result<[f64; 3], Problem> {
    let numbers = |key: &str, len: usize| -> Result<Option<Vec<f64>>, Problem> {
        let Some(values) = node[key].as_array() else {
            return match node[key] {
                Value::Null => Ok(None),
                _ => Err(Problem::malformed(format_args!("node {n}: bad {key}"))),
            };
        };
        let numbers: Option<Vec<f64>> = values
            .iter()
            .map(|v| v.as_f64().filter(|c| c.is_finite()))
            .collect();
        match numbers {
            Some(numbers) if numbers.len() == len => Ok(Some(numbers)),
            _ => Err(Problem::malformed(format_args!("node {n}: bad {key}"))),
        }
    };
    let refuse = |key: &str| {
        Problem::unsupported(format_args!(
            "node {n} has a {key} other than the identity; only translations are read"
        ))
    };
    if numbers("rotation", 4)?.is_some_and(|q| q[..3] != [0.0; 3] || q[3].abs() != 1.0) {
        return Err(refuse("rotation"));
    }
    if numbers("scale", 3)?.is_some_and(|s| s != [1.0; 3]) {
        return Err(refuse("scale"));
    }
    let mut t = numbers("translation", 3)?.map_or([0.0; 3], |t| [t[0], t[1], t[2]]);
    if let Some(m) = numbers("matrix", 16)? {
        // Column-major: the identity in the first three columns, the translation in the
        // fourth.
        let linear = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        if m[..12] != linear || m[15] != 1.0 {
            return Err(refuse("matrix"));
        }
        t = [0, 1, 2].map(|k| t[k] + m[12 + k]);
    }
    Ok(t)
}

impl Gltf<'_> {
    /// The meshes of the default scene's nodes (or, without scenes, of every node no
    /// other node has as a child), each moved by its own and its ancestors' translations.
    fn mesh(&self) -> Result<Mesh, Problem> {
        let mut mesh = Mesh::default();
        let nodes = self.root["nodes"]
            .as_array()
            .map(Vec::as_slice)
            .unwrap_or(&[]);
        for node in nodes {
            if let Some(extras) = node["extras"].as_object() {
                if mesh.crs_wkt.is_none() {
                    mesh.crs_wkt = extras
                        .get("crs_wkt")
                        .and_then(Value::as_str)
                        .map(str::to_owned);
                }
                if mesh.epsg.is_none() {
                    mesh.epsg = extras
                        .get("epsg")
                        .and_then(Value::as_u64)
                        .and_then(|e| u32::try_from(e).ok());
                }
            }
        }
        let roots: Vec<usize> = match self.root["scenes"].as_array() {
            Some(scenes) if !scenes.is_empty() => {
                let scene = match &self.root["scene"] {
                    Value::Null => 0,
                    index => usize_of(index, "the scene")?,
                };
                let scene = scenes
                    .get(scene)
                    .ok_or_else(|| Problem::malformed(format_args!("no scene {scene}")))?;
                scene["nodes"]
                    .as_array()
                    .map(Vec::as_slice)
                    .unwrap_or(&[])
                    .iter()
                    .map(|n| usize_of(n, "a scene's node"))
                    .collect::<Result<_, _>>()?
            }
            _ => {
                let mut child = vec![false; nodes.len()];
                for node in nodes {
                    for c in node["children"]
                        .as_array()
                        .map(Vec::as_slice)
                        .unwrap_or(&[])
                    {
                        if let Some(flag) = c.as_u64().and_then(|c| child.get_mut(c as usize)) {
                            *flag = true;
                        }
                    }
                }
                let roots: Vec<usize> = (0..nodes.len()).filter(|&n| !child[n]).collect();
                if roots.is_empty() && !nodes.is_empty() {
                    return Err(Problem::malformed(
                        "every node is another's child (a cycle), so no node is a root",
                    ));
                }
                roots
            }
        };
        // Depth first; a node met twice (a cycle, or a node used twice) is refused.
        let mut seen = vec![false; nodes.len()];
        let mut stack: Vec<(usize, [f64; 3])> =
            roots.into_iter().rev().map(|n| (n, [0.0; 3])).collect();
        while let Some((n, parent)) = stack.pop() {
            let node = nodes
                .get(n)
                .ok_or_else(|| Problem::malformed(format_args!("no node {n}")))?;
            if std::mem::replace(&mut seen[n], true) {
                return Err(Problem::unsupported(format_args!(
                    "node {n} is reached twice; each node is read once"
                )));
            }
            let own = translation_of(node, n)?;
            let t = [0, 1, 2].map(|k| parent[k] + own[k]);
            if !node["mesh"].is_null() {
                let m = usize_of(&node["mesh"], "a node's mesh")?;
                let primitives =
                    self.root["meshes"][m]["primitives"]
                        .as_array()
                        .ok_or_else(|| {
                            Problem::malformed(format_args!("mesh {m} has no primitives"))
                        })?;
                for primitive in primitives {
                    self.primitive(primitive, t, &mut mesh)?;
                }
            }
            let children = node["children"]
                .as_array()
                .map(Vec::as_slice)
                .unwrap_or(&[]);
            for c in children.iter().rev() {
                stack.push((usize_of(c, "a node's child")?, t));
            }
        }
        Ok(mesh)
    }

    fn primitive(&self, primitive: &Value, t: [f64; 3], mesh: &mut Mesh) -> Result<(), Problem> {
        let mode = primitive["mode"].as_u64().unwrap_or(4);
        if mode != 4 {
            return Err(Problem::unsupported(format_args!(
                "primitive mode {mode}; only triangles (4) are read"
            )));
        }
        let position = usize_of(&primitive["attributes"]["POSITION"], "POSITION")?;
        let positions = self.accessor(position, FLOAT, "VEC3")?;
        let first = mesh.vertices.len();
        for p in positions.chunks_exact(3) {
            let g = [0, 1, 2].map(|i| p[i] as f32);
            if g.iter().any(|c| !c.is_finite()) {
                return Err(Problem::malformed("a position is not finite"));
            }
            let (px, py, pz) = (f64::from(g[0]), f64::from(g[1]), f64::from(g[2]));
            mesh.vertices.push([t[0] + px, -(t[2] + pz), t[1] + py]);
        }
        let count = positions.len() / 3;
        // Application-specific float attributes (`_NAME`), read as `NAME`.
        if let Some(semantics) = primitive["attributes"].as_object() {
            for (semantic, accessor) in semantics {
                let Some(name) = semantic.strip_prefix('_') else {
                    continue;
                };
                let accessor = usize_of(accessor, "an attribute's accessor")?;
                if self.root["accessors"][accessor]["componentType"].as_u64() != Some(FLOAT)
                    || self.root["accessors"][accessor]["type"].as_str() != Some("SCALAR")
                {
                    continue;
                }
                let values = self.accessor(accessor, FLOAT, "SCALAR")?;
                if values.len() != count {
                    return Err(Problem::malformed(format_args!(
                        "attribute {semantic} has {} values for {count} vertices",
                        values.len()
                    )));
                }
                match mesh.attributes.iter_mut().find(|(n, _)| n == name) {
                    Some((_, all)) => all.extend(values),
                    None if first == 0 => mesh.attributes.push((name.to_owned(), values)),
                    None => {
                        return Err(Problem::unsupported(format_args!(
                            "attribute {semantic} in some primitives only"
                        )))
                    }
                }
            }
        }
        let indices: Vec<f64> = if primitive["indices"].is_null() {
            (0..count).map(|i| i as f64).collect()
        } else {
            let accessor = usize_of(&primitive["indices"], "indices")?;
            self.accessor(accessor, 0, "SCALAR")?
        };
        if !indices.len().is_multiple_of(3) {
            return Err(Problem::malformed("the index count is not a multiple of 3"));
        }
        for corners in indices.chunks_exact(3) {
            let mut triangle = [0u32; 3];
            for (index, &corner) in triangle.iter_mut().zip(corners) {
                let i = corner as usize;
                if i >= count {
                    return Err(Problem::malformed(format_args!(
                        "index {i} out of range: the primitive has {count} vertices"
                    )));
                }
                *index = u32::try_from(first + i)
                    .map_err(|_| Problem::unsupported("more than 2^32 vertices"))?;
            }
            mesh.triangles.push(triangle);
        }
        Ok(())
    }

    /// The values of accessor `index` (of `component` type, or any integer type when 0),
    /// as `f64` (exact for every type read).
    fn accessor(&self, index: usize, component: u64, kind: &str) -> Result<Vec<f64>, Problem> {
        let accessor = &self.root["accessors"][index];
        let bad = |what: &str| Problem::malformed(format_args!("accessor {index}: {what}"));
        if accessor["type"].as_str() != Some(kind) {
            return Err(bad(&format!("type is not {kind}")));
        }
        if !accessor["sparse"].is_null() {
            return Err(Problem::unsupported("sparse accessors"));
        }
        let component_type = accessor["componentType"].as_u64().unwrap_or(0);
        let size = match (component, component_type) {
            (FLOAT, FLOAT) => 4,
            (0, UNSIGNED_BYTE) => 1,
            (0, UNSIGNED_SHORT) => 2,
            (0, UNSIGNED_INT) => 4,
            _ => return Err(bad(&format!("unexpected component type {component_type}"))),
        };
        let width = if kind == "VEC3" { 3 } else { 1 };
        let count = usize_of(&accessor["count"], "an accessor's count")?;
        let view = &self.root["bufferViews"][usize_of(&accessor["bufferView"], "bufferView")?];
        if view["buffer"].as_u64() != Some(0) {
            return Err(Problem::unsupported("buffers other than the GLB's own"));
        }
        let view_offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let view_len = usize_of(&view["byteLength"], "a bufferView's byteLength")?;
        let offset = accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
        let element = size * width;
        let stride = view["byteStride"].as_u64().map_or(element, |s| s as usize);
        let end = view_offset
            .checked_add(view_len)
            .filter(|&end| end <= self.bin.len())
            .ok_or_else(|| bad("its bufferView runs past the binary chunk"))?;
        let needed = match count {
            0 => 0,
            n => (n - 1)
                .checked_mul(stride)
                .and_then(|v| v.checked_add(offset.checked_add(element)?))
                .ok_or_else(|| bad("too large"))?,
        };
        if stride < element || needed > view_len {
            return Err(bad("runs past its bufferView"));
        }
        let data = &self.bin[view_offset..end];
        let mut values = Vec::with_capacity(count * width);
        for i in 0..count {
            for k in 0..width {
                let at = offset + i * stride + k * size;
                let b = &data[at..at + size];
                values.push(match (component_type, size) {
                    (FLOAT, _) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    (_, 1) => f64::from(b[0]),
                    (_, 2) => f64::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                });
            }
        }
        Ok(values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_to_vec(mesh: MeshRef<'_>, origin: LocalOrigin, normals: bool) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh, origin, normals).expect("writing to a Vec");
        bytes
    }

    const VERTICES: [[f64; 3]; 4] = [
        [1_200_000.0, 500_000.0, 812.25],
        [1_200_050.0, 500_000.0, 820.0],
        [1_200_050.0, 500_050.0, 799.5],
        [1_200_000.0, 500_050.0, 805.0],
    ];
    const TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

    #[test]
    fn round_trip_gives_the_quantized_positions() -> Result<(), Problem> {
        for normals in [false, true] {
            let origin = LocalOrigin::of_points(&VERTICES);
            let mesh = MeshRef::new(&VERTICES, &TRIANGLES)
                .with_crs_wkt("PROJCS[\"x\"]")
                .with_epsg(3005);
            let bytes = write_to_vec(mesh, origin, normals);
            assert_eq!(bytes.len() % 4, 0);
            assert_eq!(u32_at(&bytes, 8) as usize, bytes.len());
            let back = read(bytes.as_slice(), Some(bytes.len() as u64))?;
            let expected: Vec<[f64; 3]> = VERTICES.iter().map(|&p| origin.quantize(p)).collect();
            assert_eq!(back.vertices, expected);
            assert_eq!(back.triangles, TRIANGLES);
            assert_eq!(back.crs_wkt.as_deref(), Some("PROJCS[\"x\"]"));
            assert_eq!(back.epsg, Some(3005));
        }
        Ok(())
    }

    #[test]
    fn json_states_origin_axes_and_exact_bounds() -> Result<(), Problem> {
        let origin = LocalOrigin::new([1_200_025.0, 500_025.0, 810.0]);
        let bytes = write_to_vec(MeshRef::new(&VERTICES, &TRIANGLES), origin, false);
        let json_len = u32_at(&bytes, 12) as usize;
        let root: Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON");
        assert_eq!(
            root["nodes"][0]["translation"],
            json!([1_200_025.0, 810.0, -500_025.0])
        );
        assert_eq!(root["accessors"][0]["min"], json!([-25.0, -10.5, -25.0]));
        assert_eq!(root["accessors"][0]["max"], json!([25.0, 10.0, 25.0]));
        assert_eq!(root["accessors"][1]["componentType"], json!(UNSIGNED_SHORT));
        Ok(())
    }

    #[test]
    fn normals_point_up_for_a_gentle_surface() {
        let local: Vec<[f32; 3]> = VERTICES
            .iter()
            .map(|&p| LocalOrigin::of_points(&VERTICES).to_local(p))
            .collect();
        for n in vertex_normals(&local, &TRIANGLES) {
            let length = n.iter().map(|c| f64::from(*c).powi(2)).sum::<f64>().sqrt();
            assert!((length - 1.0).abs() < 1e-6);
            assert!(n[2] > 0.9, "{n:?}");
        }
    }

    /// The JSON and BIN chunks of a GLB.
    fn unpack(bytes: &[u8]) -> (Value, Vec<u8>) {
        let json_len = u32_at(bytes, 12) as usize;
        let root = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON");
        let bin_at = 20 + json_len;
        let bin_len = u32_at(bytes, bin_at) as usize;
        (root, bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec())
    }

    /// A GLB of `root` and `bin`.
    fn pack(root: &Value, bin: &[u8]) -> Vec<u8> {
        let mut json = serde_json::to_vec(root).expect("JSON");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::new();
        for word in [MAGIC, 2, total as u32, json.len() as u32, CHUNK_JSON] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(bin);
        out
    }

    #[test]
    fn translations_through_parents_and_identity_transforms_are_read() -> Result<(), Problem> {
        let origin = LocalOrigin::of_points(&VERTICES);
        let bytes = write_to_vec(MeshRef::new(&VERTICES, &TRIANGLES), origin, false);
        let expected = read(bytes.as_slice(), None)?;
        let (root, bin) = unpack(&bytes);
        let node = root["nodes"][0].clone();
        let t = node["translation"].clone();
        let half = |k: usize| t[k].as_f64().unwrap() / 2.0;
        let mut child = node.clone();
        child.as_object_mut().unwrap().remove("translation");
        child["scale"] = json!([1.0, 1.0, 1.0]);
        child["rotation"] = json!([0.0, 0.0, 0.0, 1.0]);
        child["matrix"] = json!([
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            half(0),
            half(1),
            half(2),
            1.0
        ]);
        let parent = json!({ "children": [1], "translation": [half(0), half(1), half(2)] });
        // Node 2 uses the mesh too but is in no scene: not read.
        let mut moved = root.clone();
        moved["nodes"] = json!([parent, child, node]);
        moved["scenes"] = json!([{ "nodes": [0] }]);
        let back = read(pack(&moved, &bin).as_slice(), None)?;
        assert_eq!(back.vertices, expected.vertices);
        assert_eq!(back.triangles, expected.triangles);
        // A real scale, or a node reached twice, is refused.
        let mut scaled = moved.clone();
        scaled["nodes"][1]["scale"] = json!([2.0, 1.0, 1.0]);
        assert!(matches!(
            read(pack(&scaled, &bin).as_slice(), None),
            Err(Problem::Unsupported(reason)) if reason.contains("scale")
        ));
        let mut cycle = moved.clone();
        cycle["nodes"][1]["children"] = json!([0]);
        assert!(read(pack(&cycle, &bin).as_slice(), None).is_err());
        // Without scenes the roots are the nodes no node has as a child: none in a cycle.
        cycle.as_object_mut().unwrap().remove("scenes");
        let two = json!([cycle["nodes"][0].clone(), cycle["nodes"][1].clone()]);
        cycle["nodes"] = two;
        assert!(read(pack(&cycle, &bin).as_slice(), None).is_err());
        Ok(())
    }

    #[test]
    fn empty_mesh_and_broken_files() -> Result<(), Problem> {
        let bytes = write_to_vec(MeshRef::new(&[], &[]), LocalOrigin::new([0.0; 3]), true);
        assert_eq!(
            read(bytes.as_slice(), Some(bytes.len() as u64))?,
            Mesh::default()
        );
        let good = write_to_vec(
            MeshRef::new(&VERTICES, &TRIANGLES),
            LocalOrigin::of_points(&VERTICES),
            true,
        );
        for cut in [0, 10, 20, 40, good.len() - 4] {
            assert!(
                read(&good[..cut], Some(cut as u64)).is_err(),
                "cut at {cut}"
            );
        }
        let mut corrupt = good.clone();
        corrupt[0] = b'x';
        assert!(matches!(
            read(corrupt.as_slice(), None),
            Err(Problem::Malformed(_))
        ));
        let mut trailing = good.clone();
        trailing.extend_from_slice(&[0; 8]);
        assert!(matches!(
            read(trailing.as_slice(), Some(trailing.len() as u64)),
            Err(Problem::Malformed(m)) if m.contains("the file has")
        ));
        let (mut root, bin) = unpack(&good);
        assert!(read(pack(&root, &bin).as_slice(), None).is_ok());
        let mut far = root.clone();
        far["accessors"][0]["byteOffset"] = Value::from(u64::MAX);
        assert!(matches!(
            read(pack(&far, &bin).as_slice(), None),
            Err(Problem::Malformed(m)) if m.contains("too large")
        ));
        root["asset"]["version"] = Value::from("3.0");
        assert!(matches!(
            read(pack(&root, &bin).as_slice(), None),
            Err(Problem::Unsupported(m)) if m.contains("3.0")
        ));
        root.as_object_mut().expect("object").remove("asset");
        assert!(matches!(
            read(pack(&root, &bin).as_slice(), None),
            Err(Problem::Malformed(m)) if m.contains("asset.version")
        ));
        for position in (0..good.len()).step_by(7) {
            let mut corrupt = good.clone();
            corrupt[position] ^= 0xA5;
            let _ = read(corrupt.as_slice(), Some(corrupt.len() as u64));
        }
        Ok(())
    }
}

#[cfg(test)]
mod attribute_tests {
    use super::*;
    use crate::VertexAttribute;

    #[test]
    fn vertex_attributes_are_float_attributes_read_back() {
        // An odd triangle count, so that u16 indices end off a 4-byte boundary: the
        // attributes come before them and stay aligned.
        let vertices = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]];
        let triangles = [[0, 1, 2]];
        let (a, b) = ([0.5, -2.0, 7.25], [255.0, 0.0, 1e6]);
        let attributes = [
            VertexAttribute {
                name: "band_2",
                values: &a,
            },
            VertexAttribute {
                name: "dtm",
                values: &b,
            },
        ];
        let mut bytes = Vec::new();
        let mesh = MeshRef::new(&vertices, &triangles).with_attributes(&attributes);
        write(&mut bytes, mesh, LocalOrigin::new([0.0; 3]), true).unwrap();
        let json_len = u32_at(&bytes, 12) as usize;
        let root: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let semantics = &root["meshes"][0]["primitives"][0]["attributes"];
        assert!(
            semantics["_BAND_2"].is_u64() && semantics["_DTM"].is_u64(),
            "{root}"
        );
        for view in root["bufferViews"].as_array().unwrap() {
            let target = view["target"].as_u64().unwrap();
            assert!(target == 34963 || view["byteOffset"].as_u64().unwrap() % 4 == 0);
        }
        let read = read(&bytes[..], Some(bytes.len() as u64)).unwrap();
        assert_eq!(read.triangles, triangles);
        assert_eq!(read.attribute("BAND_2"), Some(&a[..]));
        assert_eq!(read.attribute("DTM"), Some(&b[..]));
    }
}
