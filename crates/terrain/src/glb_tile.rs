//! One 3D Tiles terrain tile as glTF binary (`.glb`), as CesiumJS's
//! `Cesium3DTilesTerrainProvider` reads it: one node whose `matrix` is the translation to
//! the tile's centre (ECEF, in glTF's Y-up axes), one indexed triangle primitive with
//! float32 `POSITION`s relative to it (and `NORMAL`s when asked), and the vertices on the
//! tile's west, south, east and north edges as the `CESIUM_tile_edges` extension's
//! `left`, `bottom`, `right` and `top` accessors. The tile's height range, bounding sphere
//! and horizon occlusion point go to the subtree's metadata ([`TileBounds`]), not the GLB.
//! A water mask, when given, is a greyscale PNG property texture of `EXT_structural_metadata`
//! whose property has the `WATERMASK` semantic, declared at the document level, where the
//! provider's `requestWaterMask` reads it; no primitive references it and the primitive
//! has no `TEXCOORD_0` (the mask spans the tile's rectangle, which the provider knows).
//!
//! Follows CesiumJS 1.140's `Cesium3DTilesTerrainGeometryProcessor.js`: it reads
//! `nodes[0].matrix`, maps it from Y-up to Z-up (`Axis.Y_UP_TO_Z_UP`, glTF `(x, y, z)` is
//! ECEF `(x, -z, y)`), reads positions and normals as tightly packed float32 and indices
//! as `UNSIGNED_SHORT` or `UNSIGNED_INT`.

use serde_json::{json, Value};

use crate::quantized_mesh::{
    bounding_sphere, check_triangles_and_normals, edge_lists, first_use_order, geodetic_to_ecef,
    horizon_occlusion_point, EncodeError, GeoRectangle, QUANTIZED_MAX,
};

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The glTF extension naming the tile's edge vertices.
pub const TILE_EDGES_EXTENSION: &str = "CESIUM_tile_edges";

/// The glTF extension a water mask is written in (a property texture).
pub const STRUCTURAL_METADATA_EXTENSION: &str = "EXT_structural_metadata";

/// What the subtree's tile metadata says of a tile (the semantics CesiumJS reads).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TileBounds {
    /// `TILE_MINIMUM_HEIGHT`: at or below the lowest vertex height (m above the
    /// ellipsoid), float32 rounding of the positions included.
    pub min_height: f64,
    /// `TILE_MAXIMUM_HEIGHT`: at or above the highest vertex height, likewise.
    pub max_height: f64,
    /// `TILE_BOUNDING_SPHERE`: ECEF centre and radius holding every vertex, likewise.
    pub sphere: [f64; 4],
    /// `TILE_HORIZON_OCCLUSION_POINT`: in ellipsoid-scaled ECEF, as quantized-mesh's.
    pub horizon_occlusion_point: [f64; 3],
}

/// One terrain tile, ready to encode as GLB.
///
/// Vertices are `[u, v, _]` as a quantized-mesh tile's (u from west 0 to east 32767, v
/// from south to north; the third value is not read) with each vertex's height in
/// `heights`; triangles are counter-clockwise seen from above.
#[derive(Debug, Clone)]
pub struct GlbTile<'a> {
    rectangle: GeoRectangle,
    vertices: &'a [[u16; 3]],
    heights: &'a [f64],
    triangles: &'a [[u32; 3]],
    normals: Option<&'a [[f64; 3]]>,
    water_mask: Option<&'a [u8]>,
}

impl<'a> GlbTile<'a> {
    /// A tile without normals.
    pub fn new(
        rectangle: GeoRectangle,
        vertices: &'a [[u16; 3]],
        heights: &'a [f64],
        triangles: &'a [[u32; 3]],
    ) -> Self {
        GlbTile {
            rectangle,
            vertices,
            heights,
            triangles,
            normals: None,
            water_mask: None,
        }
    }

    /// Adds a water mask as the quantized-mesh extension has it: 1 byte (0 all land, 255
    /// all water) or 256 x 256, rows north to south. An all-land mask writes nothing
    /// (CesiumJS takes a tile without one as land).
    pub fn with_water_mask(mut self, mask: &'a [u8]) -> Self {
        self.water_mask = Some(mask);
        self
    }

    /// Adds `NORMAL`s: one ECEF unit normal per vertex, in the input order.
    pub fn with_normals(mut self, normals: &'a [[f64; 3]]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// The ECEF position of vertex `v` of height `h` (the position CesiumJS's tile
    /// rectangle gives its u, v).
    fn ecef(&self, v: [u16; 3], h: f64) -> [f64; 3] {
        let r = self.rectangle;
        let t = |q: u16| f64::from(q) / f64::from(QUANTIZED_MAX);
        let lon = r.west + (r.east - r.west) * t(v[0]);
        let lat = r.south + (r.north - r.south) * t(v[1]);
        geodetic_to_ecef(lon, lat, h)
    }

    /// The GLB bytes and the tile's metadata.
    ///
    /// # Guarantees
    /// - Vertices are renumbered in order of first use by the triangles, unused ones
    ///   dropped (as [`crate::QuantizedMeshTile::encode`] does); triangles keep their order.
    /// - Each position is `f32(ecef - centre)` in glTF axes, `centre` (the bounding
    ///   sphere's, f64 in the node matrix) added back exactly as CesiumJS does.
    /// - Indices (and edge indices) are 16-bit below 65535 vertices, 32-bit from there.
    /// - Edges hold every vertex with u = 0 (left), v = 0 (bottom), u = 32767 (right),
    ///   v = 32767 (top), in quantized-mesh's order; each is non-empty (a tile without a
    ///   vertex on one of its edges is refused, as CesiumJS could not skirt it).
    /// - Same tile in, same bytes out.
    pub fn encode(&self) -> Result<(Vec<u8>, TileBounds), EncodeError> {
        self.check()?;
        let (order, triangles) = first_use_order(self.vertices.len(), self.triangles);
        let vertices: Vec<[u16; 3]> = order.iter().map(|&i| self.vertices[i]).collect();
        let heights: Vec<f64> = order.iter().map(|&i| self.heights[i]).collect();
        let n = vertices.len();
        let ecef: Vec<[f64; 3]> = vertices
            .iter()
            .zip(&heights)
            .map(|(&v, &h)| self.ecef(v, h))
            .collect();
        let (centre, radius) = bounding_sphere(&ecef, self.rectangle);
        let hop = horizon_occlusion_point(&ecef, centre);
        let (min_height, max_height) = heights
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            });
        let edges = edge_lists(&vertices);
        if let Some(k) = edges.iter().position(Vec::is_empty) {
            return Err(EncodeError::EmptyEdge(
                ["west", "south", "east", "north"][k],
            ));
        }

        let mut bin = Builder::default();
        // Z-up ECEF offsets to glTF's Y-up axes: (x, y, z) -> (x, z, -y).
        let local: Vec<[f32; 3]> = ecef
            .iter()
            .map(|p| {
                let d = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
                [d[0] as f32, d[2] as f32, -d[1] as f32]
            })
            .collect();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in &local {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let position = bin.accessor(
            local.iter().flatten().flat_map(|c| c.to_le_bytes()),
            Some(ARRAY_BUFFER),
            json!({"componentType": FLOAT, "count": n, "type": "VEC3",
                   "min": lo, "max": hi}),
        );
        let mut attributes = json!({ "POSITION": position });
        if let Some(normals) = self.normals {
            let normals: Vec<[f32; 3]> = order
                .iter()
                .map(|&i| {
                    let m = normals[i];
                    [m[0] as f32, m[2] as f32, -m[1] as f32]
                })
                .collect();
            attributes["NORMAL"] = bin
                .accessor(
                    normals.iter().flatten().flat_map(|c| c.to_le_bytes()),
                    Some(ARRAY_BUFFER),
                    json!({"componentType": FLOAT, "count": n, "type": "VEC3"}),
                )
                .into();
        }
        let wide = n >= 65_535;
        let mut index_accessor = |indices: &mut dyn Iterator<Item = u32>, target| {
            let indices: Vec<u32> = indices.collect();
            let count = indices.len();
            let (bytes, component): (Vec<u8>, u32) = if wide {
                let b = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
                (b, UNSIGNED_INT)
            } else {
                let b = indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect();
                (b, UNSIGNED_SHORT)
            };
            bin.accessor(
                bytes,
                target,
                json!({"componentType": component, "count": count, "type": "SCALAR"}),
            )
        };
        let indices = index_accessor(
            &mut triangles.iter().flatten().copied(),
            Some(ELEMENT_ARRAY_BUFFER),
        );
        let [west, south, east, north] =
            edges.map(|edge| index_accessor(&mut edge.into_iter(), None));

        // Column-major: the translation to the centre, in glTF axes.
        let matrix = [
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, centre[0], centre[2],
            -centre[1], 1.0,
        ];
        let mut document = json!({
            "asset": {"version": "2.0", "generator": "tinsmith"},
            "extensionsUsed": [TILE_EDGES_EXTENSION],
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "matrix": matrix}],
            "meshes": [{"primitives": [{
                "attributes": attributes,
                "indices": indices,
                "mode": 4,
                "extensions": {TILE_EDGES_EXTENSION: {
                    "left": west, "bottom": south, "right": east, "top": north,
                }},
            }]}],
        });
        if let Some(mask) = self.water_mask.filter(|m| m.iter().any(|&cell| cell != 0)) {
            bin.water_mask(mask, &mut document)?;
        }
        document["accessors"] = std::mem::take(&mut bin.accessors).into();
        document["bufferViews"] = std::mem::take(&mut bin.views).into();
        document["buffers"] = json!([{"byteLength": bin.bytes.len()}]);
        // Rounding an offset of at most `radius` to float32 moves a vertex by at most
        // `radius x 2^-24`: the bounds are widened by twice that, so that they hold the
        // vertices the client decodes, not only the exact ones.
        let pad = radius * f64::from(f32::EPSILON);
        let bounds = TileBounds {
            min_height: min_height - pad,
            max_height: max_height + pad,
            sphere: [centre[0], centre[1], centre[2], radius + pad],
            horizon_occlusion_point: hop,
        };
        Ok((glb(&document, &bin.bytes), bounds))
    }

    fn check(&self) -> Result<(), EncodeError> {
        let r = self.rectangle;
        let corners = [r.west, r.south, r.east, r.north];
        if !corners.iter().all(|c| c.is_finite()) || r.west >= r.east || r.south >= r.north {
            return Err(EncodeError::Rectangle(corners));
        }
        let vertex_count = self.vertices.len();
        if self.heights.len() != vertex_count {
            return Err(EncodeError::HeightCount {
                expected: vertex_count,
                got: self.heights.len(),
            });
        }
        if let Some(&h) = self.heights.iter().find(|h| !h.is_finite()) {
            return Err(EncodeError::HeightRange {
                min: h as f32,
                max: h as f32,
            });
        }
        for (vertex, v) in self.vertices.iter().enumerate() {
            if let Some(&value) = v[..2].iter().find(|&&q| q > QUANTIZED_MAX) {
                return Err(EncodeError::ValueOutOfRange { vertex, value });
            }
        }
        check_triangles_and_normals(self.triangles, vertex_count, self.normals)?;
        if let Some(mask) = self.water_mask {
            if mask.len() != 1 && mask.len() != 65_536 {
                return Err(EncodeError::WaterMaskSize(mask.len()));
            }
        }
        Ok(())
    }
}

/// The binary buffer being filled, with its buffer views and accessors.
#[derive(Default)]
struct Builder {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends `data` (at a multiple of 4 bytes) as a buffer view of its own and an
    /// accessor over it described by `accessor`; returns the accessor's index.
    fn accessor(
        &mut self,
        data: impl IntoIterator<Item = u8>,
        target: Option<u32>,
        mut accessor: Value,
    ) -> usize {
        accessor["bufferView"] = self.view(data, target).into();
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends `data` (at a multiple of 4 bytes) as a buffer view of its own; returns the
    /// view's index.
    fn view(&mut self, data: impl IntoIterator<Item = u8>, target: Option<u32>) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend(data);
        let length = self.bytes.len() - offset;
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": length});
        if let Some(target) = target {
            view["target"] = target.into();
        }
        self.views.push(view);
        self.views.len() - 1
    }
}

impl Builder {
    /// Adds `mask` (1 or 256 x 256 bytes, rows north to south) to `document` as a
    /// greyscale PNG in a buffer view of its own, the texture of an
    /// `EXT_structural_metadata` property texture whose one property is `WATERMASK`
    /// (normalized UINT8 in the red channel, which CesiumJS samples).
    fn water_mask(&mut self, mask: &[u8], document: &mut Value) -> Result<(), EncodeError> {
        let side = if mask.len() == 1 { 1 } else { 256 };
        let mut png_bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut png_bytes, side, side);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let written = encoder
            .write_header()
            .and_then(|mut w| w.write_image_data(mask));
        written.map_err(|e| EncodeError::WaterMaskImage(e.to_string()))?;
        let view = self.view(png_bytes, None);
        document["extensionsUsed"]
            .as_array_mut()
            .expect("extensionsUsed is a list")
            .push(STRUCTURAL_METADATA_EXTENSION.into());
        document["images"] = json!([{"bufferView": view, "mimeType": "image/png"}]);
        // LINEAR, CLAMP_TO_EDGE: as CesiumJS samples a quantized-mesh tile's mask.
        document["samplers"] =
            json!([{"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071}]);
        document["textures"] = json!([{"source": 0, "sampler": 0}]);
        document["extensions"] = json!({STRUCTURAL_METADATA_EXTENSION: {
            "schema": {"id": "terrain", "classes": {"water": {"properties": {"mask": {
                "type": "SCALAR", "componentType": "UINT8", "normalized": true,
                "semantic": "WATERMASK",
            }}}}},
            "propertyTextures": [{"class": "water", "properties": {"mask": {
                "index": 0, "texCoord": 0, "channels": [0],
            }}}],
        }});
        Ok(())
    }
}

/// The GLB container of `document` and its binary buffer `bin` (a multiple of 4 bytes).
fn glb(document: &Value, bin: &[u8]) -> Vec<u8> {
    let text = serde_json::to_vec(document).expect("glTF JSON serializes");
    let mut out = Vec::with_capacity(28 + text.len() + 3 + bin.len());
    tinsmith_formats::write_glb_start(&mut out, &text, Some(bin.len() as u64))
        .expect("a tile is far below 4 GiB, and a Vec takes every write");
    out.extend_from_slice(bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> GeoRectangle {
        GeoRectangle {
            west: 10.0,
            south: 45.0,
            east: 11.0,
            north: 46.0,
        }
    }

    /// The JSON chunk of a GLB.
    fn document(bytes: &[u8]) -> Value {
        let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + length]).unwrap()
    }

    #[test]
    fn a_square_has_its_edges_and_positions_round_trip() {
        let m = QUANTIZED_MAX;
        let vertices = [[0, 0, 0], [m, 0, 0], [m, m, 0], [0, m, 0]];
        let heights = [100.0, 200.0, 300.0, 400.0];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let (bytes, bounds) = GlbTile::new(rect(), &vertices, &heights, &triangles)
            .encode()
            .unwrap();
        assert_eq!(bytes.len() % 4, 0);
        assert_eq!(&bytes[..4], b"glTF");
        let doc = document(&bytes);
        let edges = &doc["meshes"][0]["primitives"][0]["extensions"][TILE_EDGES_EXTENSION];
        for side in ["left", "bottom", "right", "top"] {
            let accessor = edges[side].as_u64().unwrap() as usize;
            assert_eq!(doc["accessors"][accessor]["count"], 2, "{side}");
        }
        let pad = bounds.sphere[3] * f64::from(f32::EPSILON);
        assert!(bounds.min_height < 100.0 && bounds.min_height >= 100.0 - pad);
        assert!(bounds.max_height > 400.0 && bounds.max_height <= 400.0 + pad);
        // The first position, back in ECEF, is the south-west corner.
        let m = doc["nodes"][0]["matrix"].as_array().unwrap();
        let t: Vec<f64> = m[12..15].iter().map(|v| v.as_f64().unwrap()).collect();
        let json_length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let bin = &bytes[20 + json_length + 8..];
        let f = |k: usize| {
            f64::from(f32::from_le_bytes(
                bin[4 * k..4 * k + 4].try_into().unwrap(),
            ))
        };
        let ecef = [t[0] + f(0), -(t[2] + f(2)), t[1] + f(1)];
        let want = geodetic_to_ecef(10.0, 45.0, 100.0);
        for k in 0..3 {
            assert!((ecef[k] - want[k]).abs() < 0.01, "{ecef:?} {want:?}");
        }
    }

    #[test]
    fn from_65535_vertices_indices_are_32_bit() {
        // A 256 x 256 lattice: 65,536 vertices, all used.
        let n = 256u32;
        let at = |i: u32| (i * u32::from(QUANTIZED_MAX) / (n - 1)) as u16;
        let vertices: Vec<[u16; 3]> = (0..n * n).map(|k| [at(k % n), at(k / n), 0]).collect();
        let heights = vec![0.0; vertices.len()];
        let triangles: Vec<[u32; 3]> = (0..n - 1)
            .flat_map(|j| (0..n - 1).map(move |i| (i, j)))
            .flat_map(|(i, j)| {
                let k = j * n + i;
                [[k, k + 1, k + n + 1], [k, k + n + 1, k + n]]
            })
            .collect();
        let (bytes, _) = GlbTile::new(rect(), &vertices, &heights, &triangles)
            .encode()
            .unwrap();
        let doc = document(&bytes);
        let primitive = &doc["meshes"][0]["primitives"][0];
        let indices = primitive["indices"].as_u64().unwrap() as usize;
        assert_eq!(doc["accessors"][indices]["componentType"], UNSIGNED_INT);
        let left = primitive["extensions"][TILE_EDGES_EXTENSION]["left"]
            .as_u64()
            .unwrap() as usize;
        assert_eq!(doc["accessors"][left]["componentType"], UNSIGNED_INT);
        assert_eq!(doc["accessors"][left]["count"], n);
    }

    #[test]
    fn a_water_mask_is_a_png_property_texture_and_all_land_writes_none() {
        let m = QUANTIZED_MAX;
        let vertices = [[0, 0, 0], [m, 0, 0], [m, m, 0], [0, m, 0]];
        let heights = [0.0; 4];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let tile = || GlbTile::new(rect(), &vertices, &heights, &triangles);
        let cells: Vec<u8> = (0..65_536)
            .map(|k| if k % 256 < 100 { 255 } else { 0 })
            .collect();
        for (mask, side) in [(&[255u8][..], 1), (&cells[..], 256)] {
            let (bytes, _) = tile().with_water_mask(mask).encode().unwrap();
            let doc = document(&bytes);
            assert!(doc["extensionsUsed"]
                .as_array()
                .unwrap()
                .contains(&STRUCTURAL_METADATA_EXTENSION.into()));
            let class = &doc["extensions"][STRUCTURAL_METADATA_EXTENSION]["schema"]["classes"]
                ["water"]["properties"]["mask"];
            assert_eq!(class["semantic"], "WATERMASK");
            let view =
                &doc["bufferViews"][doc["images"][0]["bufferView"].as_u64().unwrap() as usize];
            let json_length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            let bin = &bytes[20 + json_length + 8..];
            let at = view["byteOffset"].as_u64().unwrap() as usize;
            let png = &bin[at..at + view["byteLength"].as_u64().unwrap() as usize];
            let mut reader = png::Decoder::new(std::io::Cursor::new(png))
                .read_info()
                .unwrap();
            let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
            let info = reader.next_frame(&mut pixels).unwrap();
            assert_eq!((info.width, info.height), (side, side));
            assert_eq!(&pixels[..info.buffer_size()], mask);
        }
        let (land, _) = tile().with_water_mask(&[0]).encode().unwrap();
        let (none, _) = tile().encode().unwrap();
        assert_eq!(land, none);
        let wrong = tile().with_water_mask(&[0, 255]).encode();
        assert_eq!(wrong.unwrap_err(), EncodeError::WaterMaskSize(2));
    }

    #[test]
    fn a_tile_without_a_vertex_on_an_edge_is_refused() {
        let m = QUANTIZED_MAX;
        let vertices = [[0, 0, 0], [m, 0, 0], [0, 100, 0]];
        let heights = [0.0; 3];
        let result = GlbTile::new(rect(), &vertices, &heights, &[[0, 1, 2]]).encode();
        assert_eq!(result.unwrap_err(), EncodeError::EmptyEdge("north"));
    }
}
