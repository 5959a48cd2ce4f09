//! Cesium quantized-mesh-1.0 tiles: the encoder (header, zig-zag delta vertices,
//! high-water-mark indices, W/S/E/N edge lists, oct normals and metadata extensions).
//!
//! Follows the CesiumGS/quantized-mesh README and CesiumJS's decoder
//! (`CesiumTerrainProvider.js`, `createVerticesFromQuantizedTerrainMesh.js`); see
//! `docs/architecture.md` ("Terrain tiles") for the choices made where they leave room.

/// WGS84 semi-major axis (m).
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 semi-minor axis (m).
pub const WGS84_B: f64 = 6_356_752.314_245_179;

/// The largest quantized u, v or height value (the east, north and maximum-height end).
pub const QUANTIZED_MAX: u16 = 32767;

/// More vertices than this and indices are written as 32-bit integers (CesiumJS tests
/// `vertexCount > 64 * 1024`; the spec says "more than 65536 vertices").
pub const MAX_16BIT_VERTICES: usize = 65_536;

/// Size of the fixed header, in bytes.
pub const HEADER_BYTES: usize = 88;

/// Extension id of oct-encoded per-vertex normals (`octvertexnormals`).
pub const EXTENSION_NORMALS: u8 = 1;
/// Extension id of the water mask (`watermask`).
pub const EXTENSION_WATER_MASK: u8 = 2;
/// Extension id of the JSON metadata (`metadata`).
pub const EXTENSION_METADATA: u8 = 4;

/// What can be wrong with a tile handed to [`QuantizedMeshTile::encode`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EncodeError {
    /// A quantized u, v or height is above [`QUANTIZED_MAX`].
    #[error("vertex {vertex}: quantized value {value} is above 32767")]
    ValueOutOfRange {
        /// The vertex (input numbering).
        vertex: usize,
        /// The offending value.
        value: u16,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but the tile has {vertex_count}")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The index.
        index: u32,
        /// How many vertices there are.
        vertex_count: usize,
    },
    /// The minimum height is above the maximum, or one is not finite.
    #[error("height range {min}..{max} is not a finite, ordered range")]
    HeightRange {
        /// Minimum height.
        min: f32,
        /// Maximum height.
        max: f32,
    },
    /// A water mask is neither 1 byte nor 256 x 256.
    #[error("a water mask of {0} bytes: it is 1 or 65536")]
    WaterMaskSize(usize),
    /// A water mask could not be encoded as PNG (3D Tiles).
    #[error("the water mask's PNG: {0}")]
    WaterMaskImage(String),
    /// The normals are not one per vertex.
    #[error("{got} normals for {expected} vertices")]
    NormalCount {
        /// Vertices.
        expected: usize,
        /// Normals.
        got: usize,
    },
    /// The rectangle is empty or not finite.
    #[error("tile rectangle {0:?} is empty or not finite")]
    Rectangle([f64; 4]),
    /// The heights are not one per vertex (a GLB tile).
    #[error("{got} heights for {expected} vertices")]
    HeightCount {
        /// Vertices.
        expected: usize,
        /// Heights.
        got: usize,
    },
    /// No vertex lies on this edge of a GLB tile (`CESIUM_tile_edges` needs one).
    #[error("no vertex on the tile's {0} edge")]
    EmptyEdge(&'static str),
}

/// A tile's geodetic rectangle, in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoRectangle {
    /// West longitude.
    pub west: f64,
    /// South latitude.
    pub south: f64,
    /// East longitude.
    pub east: f64,
    /// North latitude.
    pub north: f64,
}

/// One quantized-mesh tile, ready to encode.
///
/// Vertices are `[u, v, height]`, each in `0..=32767`: u from west (0) to east (32767),
/// v from south to north, height from `min_height` to `max_height` (the float32 values the
/// header carries, which the decoder interpolates between). Triangles are
/// counter-clockwise seen from above.
#[derive(Debug, Clone)]
pub struct QuantizedMeshTile<'a> {
    rectangle: GeoRectangle,
    min_height: f32,
    max_height: f32,
    vertices: &'a [[u16; 3]],
    triangles: &'a [[u32; 3]],
    normals: Option<&'a [[f64; 3]]>,
    water_mask: Option<&'a [u8]>,
    metadata: Option<&'a str>,
}

impl<'a> QuantizedMeshTile<'a> {
    /// A tile without extensions.
    pub fn new(
        rectangle: GeoRectangle,
        min_height: f32,
        max_height: f32,
        vertices: &'a [[u16; 3]],
        triangles: &'a [[u32; 3]],
    ) -> Self {
        QuantizedMeshTile {
            rectangle,
            min_height,
            max_height,
            vertices,
            triangles,
            normals: None,
            water_mask: None,
            metadata: None,
        }
    }

    /// Adds the `octvertexnormals` extension (id 1): one ECEF unit normal per vertex, in
    /// the input vertex order.
    pub fn with_normals(mut self, normals: &'a [[f64; 3]]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// Adds the `watermask` extension (id 2): 1 byte (0 all land, 255 all water) or
    /// 256 x 256 bytes, north to south, west to east.
    pub fn with_water_mask(mut self, mask: &'a [u8]) -> Self {
        self.water_mask = Some(mask);
        self
    }

    /// Adds the `metadata` extension (id 4) with this JSON text.
    pub fn with_metadata(mut self, json: &'a str) -> Self {
        self.metadata = Some(json);
        self
    }

    /// The uncompressed tile bytes.
    ///
    /// # Guarantees
    /// - Vertices are renumbered in order of first use by the triangles (so every
    ///   high-water-mark code is `highest - index >= 0`); vertices no triangle uses are
    ///   dropped. Triangles keep their order and their corners' order.
    /// - Indices are 16-bit for at most [`MAX_16BIT_VERTICES`] vertices, 32-bit above, with
    ///   2 zero bytes before the triangle count when needed to align them to 4 bytes.
    /// - Edge lists hold every vertex with u = 0 (west), v = 0 (south), u = 32767 (east),
    ///   v = 32767 (north), sorted as CesiumJS sorts them: west south to north, south east
    ///   to west, east north to south, north west to east.
    /// - Header: centre and bounding sphere from the ECEF box of the decoded vertices
    ///   (WGS84); horizon occlusion point in ellipsoid-scaled space as CesiumJS's
    ///   `EllipsoidalOccluder` computes it, or, when that is undefined (tiles spanning a
    ///   large part of the globe), the direction scaled far out (1e16, as Cesium World
    ///   Terrain's root tiles), which disables horizon culling for the tile.
    /// - Same tile in, same bytes out.
    pub fn encode(&self) -> Result<Vec<u8>, EncodeError> {
        self.check()?;
        let (order, triangles) = first_use_order(self.vertices.len(), self.triangles);
        let vertices: Vec<[u16; 3]> = order.iter().map(|&i| self.vertices[i]).collect();
        let n = vertices.len();
        let wide = n > MAX_16BIT_VERTICES;

        let ecef: Vec<[f64; 3]> = vertices.iter().map(|v| self.decoded_ecef(*v)).collect();
        let mut out = Vec::with_capacity(HEADER_BYTES + 4 + 6 * n + 12 * triangles.len() + 64);
        self.write_header(&mut out, &ecef);

        out.extend_from_slice(&(n as u32).to_le_bytes());
        for k in 0..3 {
            let mut previous = 0i32;
            for v in &vertices {
                let value = i32::from(v[k]);
                out.extend_from_slice(&zig_zag(value - previous).to_le_bytes());
                previous = value;
            }
        }
        if wide && out.len() % 4 != 0 {
            out.extend_from_slice(&[0, 0]);
        }
        let push_index = |out: &mut Vec<u8>, index: u32| {
            if wide {
                out.extend_from_slice(&index.to_le_bytes());
            } else {
                out.extend_from_slice(&(index as u16).to_le_bytes());
            }
        };
        out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
        let mut highest = 0u32;
        for &index in triangles.iter().flatten() {
            let code = highest - index;
            if code == 0 {
                highest += 1;
            }
            push_index(&mut out, code);
        }

        for edge in edge_lists(&vertices) {
            out.extend_from_slice(&(edge.len() as u32).to_le_bytes());
            for index in edge {
                push_index(&mut out, index);
            }
        }

        if let Some(normals) = self.normals {
            out.push(EXTENSION_NORMALS);
            out.extend_from_slice(&(2 * n as u32).to_le_bytes());
            for &i in &order {
                out.extend_from_slice(&oct_encode(normals[i]));
            }
        }
        if let Some(mask) = self.water_mask {
            out.push(EXTENSION_WATER_MASK);
            out.extend_from_slice(&(mask.len() as u32).to_le_bytes());
            out.extend_from_slice(mask);
        }
        if let Some(json) = self.metadata {
            out.push(EXTENSION_METADATA);
            out.extend_from_slice(&(4 + json.len() as u32).to_le_bytes());
            out.extend_from_slice(&(json.len() as u32).to_le_bytes());
            out.extend_from_slice(json.as_bytes());
        }
        Ok(out)
    }

    fn check(&self) -> Result<(), EncodeError> {
        let r = self.rectangle;
        let corners = [r.west, r.south, r.east, r.north];
        if !corners.iter().all(|c| c.is_finite()) || r.west >= r.east || r.south >= r.north {
            return Err(EncodeError::Rectangle(corners));
        }
        let (min, max) = (self.min_height, self.max_height);
        if !(min.is_finite() && max.is_finite() && min <= max) {
            return Err(EncodeError::HeightRange { min, max });
        }
        for (vertex, v) in self.vertices.iter().enumerate() {
            if let Some(&value) = v.iter().find(|&&q| q > QUANTIZED_MAX) {
                return Err(EncodeError::ValueOutOfRange { vertex, value });
            }
        }
        let vertex_count = self.vertices.len();
        check_triangles_and_normals(self.triangles, vertex_count, self.normals)?;
        if let Some(mask) = self.water_mask {
            if mask.len() != 1 && mask.len() != 256 * 256 {
                return Err(EncodeError::WaterMaskSize(mask.len()));
            }
        }
        Ok(())
    }

    /// The ECEF position the decoder will compute for a quantized vertex.
    fn decoded_ecef(&self, v: [u16; 3]) -> [f64; 3] {
        let r = self.rectangle;
        let t = |q: u16| f64::from(q) / f64::from(QUANTIZED_MAX);
        let lon = r.west + (r.east - r.west) * t(v[0]);
        let lat = r.south + (r.north - r.south) * t(v[1]);
        let (min, max) = (f64::from(self.min_height), f64::from(self.max_height));
        geodetic_to_ecef(lon, lat, min + (max - min) * t(v[2]))
    }

    fn write_header(&self, out: &mut Vec<u8>, ecef: &[[f64; 3]]) {
        let (centre, radius) = bounding_sphere(ecef, self.rectangle);
        let hop = horizon_occlusion_point(ecef, centre);
        for c in centre {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&self.min_height.to_le_bytes());
        out.extend_from_slice(&self.max_height.to_le_bytes());
        for c in centre {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&radius.to_le_bytes());
        for c in hop {
            out.extend_from_slice(&c.to_le_bytes());
        }
        debug_assert_eq!(out.len(), HEADER_BYTES);
    }
}

/// The libdeflate level tiles are gzipped at. Measured on the tiles of ETOPO5 z0-4, Big
/// Tujunga z0-12 and Fort Worth z0-10 against zlib's default level (flate2, before): 3.6 %,
/// 3.5 % and 5.2 % fewer bytes for 34, 39 and 2 ms of CPU (level 12: 4.1 %, 3.8 %, 5.6 %
/// for twice that; 6 and 9 gain at most 3.5 % on the small tiles and 0.7 % on the larger).
const GZIP_LEVEL: i32 = 10;

thread_local! {
    /// Each thread's compressor (one holds a few hundred kB of match-finder tables).
    static COMPRESSOR: std::cell::RefCell<libdeflater::Compressor> =
        std::cell::RefCell::new(libdeflater::Compressor::new(
            libdeflater::CompressionLvl::new(GZIP_LEVEL).expect("a level libdeflate has"),
        ));
}

/// Gzips `bytes` with libdeflate at level 10 (the gzip header carries no time or
/// name, and libdeflate's output depends only on its input and level, so the same bytes
/// in give the same bytes out on any machine).
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    COMPRESSOR.with(|compressor| {
        let mut compressor = compressor.borrow_mut();
        let mut out = vec![0; compressor.gzip_compress_bound(bytes.len())];
        let n = compressor
            .gzip_compress(bytes, &mut out)
            .expect("the bound holds any compressed size");
        out.truncate(n);
        out
    })
}

/// WGS84 geodetic (degrees, metres above the ellipsoid) to ECEF (metres).
pub fn geodetic_to_ecef(lon_deg: f64, lat_deg: f64, height: f64) -> [f64; 3] {
    let (lon, lat) = (lon_deg.to_radians(), lat_deg.to_radians());
    let e2 = 1.0 - (WGS84_B * WGS84_B) / (WGS84_A * WGS84_A);
    let n = WGS84_A / (1.0 - e2 * lat.sin() * lat.sin()).sqrt();
    [
        (n + height) * lat.cos() * lon.cos(),
        (n + height) * lat.cos() * lon.sin(),
        (n * (1.0 - e2) + height) * lat.sin(),
    ]
}

/// The geodetic surface normal (ECEF unit vector) at a longitude and latitude in degrees.
pub fn surface_normal(lon_deg: f64, lat_deg: f64) -> [f64; 3] {
    let (lon, lat) = (lon_deg.to_radians(), lat_deg.to_radians());
    [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()]
}

/// Oct-encodes a unit vector as CesiumJS's `AttributeCompression.octEncode` (range 255).
pub fn oct_encode(n: [f64; 3]) -> [u8; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    if !(l1 > 0.0 && l1.is_finite()) {
        return [128, 255]; // straight up (0, 0, 1)
    }
    let (mut x, mut y) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        let sign = |v: f64| if v < 0.0 { -1.0 } else { 1.0 };
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * sign(ox);
        y = (1.0 - ox.abs()) * sign(oy);
    }
    let byte = |v: f64| ((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 255.0).round() as u8;
    [byte(x), byte(y)]
}

fn zig_zag(d: i32) -> u16 {
    (((d << 1) ^ (d >> 31)) & 0xffff) as u16
}

/// The vertices in order of first use (old indices) and the triangles renumbered.
pub(super) fn first_use_order(
    vertex_count: usize,
    triangles: &[[u32; 3]],
) -> (Vec<usize>, Vec<[u32; 3]>) {
    let mut new_index = vec![u32::MAX; vertex_count];
    let mut order = Vec::new();
    let renumbered = triangles
        .iter()
        .map(|t| {
            t.map(|i| {
                let slot = &mut new_index[i as usize];
                if *slot == u32::MAX {
                    *slot = order.len() as u32;
                    order.push(i as usize);
                }
                *slot
            })
        })
        .collect();
    (order, renumbered)
}

/// The W, S, E, N edge lists, in CesiumJS's order.
pub(super) fn edge_lists(vertices: &[[u16; 3]]) -> [Vec<u32>; 4] {
    let on = |k: usize, value: u16| -> Vec<u32> {
        (0..vertices.len() as u32)
            .filter(|&i| vertices[i as usize][k] == value)
            .collect()
    };
    let mut west = on(0, 0);
    west.sort_by_key(|&i| vertices[i as usize][1]);
    let mut south = on(1, 0);
    south.sort_by_key(|&i| std::cmp::Reverse(vertices[i as usize][0]));
    let mut east = on(0, QUANTIZED_MAX);
    east.sort_by_key(|&i| std::cmp::Reverse(vertices[i as usize][1]));
    let mut north = on(1, QUANTIZED_MAX);
    north.sort_by_key(|&i| vertices[i as usize][0]);
    [west, south, east, north]
}

/// Centre of the ECEF box of the points and the distance to the farthest one. An empty
/// tile gets the rectangle's centre on the ellipsoid and radius 0.
pub(super) fn bounding_sphere(points: &[[f64; 3]], r: GeoRectangle) -> ([f64; 3], f64) {
    if points.is_empty() {
        let c = geodetic_to_ecef((r.west + r.east) / 2.0, (r.south + r.north) / 2.0, 0.0);
        return (c, 0.0);
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let centre = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0);
    let radius = points
        .iter()
        .map(|p| distance(*p, centre))
        .fold(0.0, f64::max);
    (centre, radius)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn scaled(p: [f64; 3]) -> [f64; 3] {
    [p[0] / WGS84_A, p[1] / WGS84_A, p[2] / WGS84_B]
}

/// CesiumJS `EllipsoidalOccluder.computeHorizonCullingPointFromVertices`, with the
/// direction towards `towards` (ECEF); in ellipsoid-scaled coordinates.
pub(super) fn horizon_occlusion_point(points: &[[f64; 3]], towards: [f64; 3]) -> [f64; 3] {
    let s = scaled(towards);
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let d = if len > 0.0 {
        s.map(|c| c / len)
    } else {
        [1.0, 0.0, 0.0]
    };
    let mut max_magnitude = 0.0f64;
    for p in points {
        let q = scaled(*p);
        let mut m2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
        let mut m = m2.sqrt();
        let dir = q.map(|c| c / m);
        m2 = m2.max(1.0);
        m = m.max(1.0);
        let cos_a = dir[0] * d[0] + dir[1] * d[1] + dir[2] * d[2];
        let cross = [
            dir[1] * d[2] - dir[2] * d[1],
            dir[2] * d[0] - dir[0] * d[2],
            dir[0] * d[1] - dir[1] * d[0],
        ];
        let sin_a = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
        let cos_b = 1.0 / m;
        let sin_b = (m2 - 1.0).sqrt() * cos_b;
        let magnitude = 1.0 / (cos_a * cos_b - sin_a * sin_b);
        if !magnitude.is_finite() || magnitude < 0.0 {
            return d.map(|c| c * 1e16);
        }
        max_magnitude = max_magnitude.max(magnitude);
    }
    d.map(|c| c * max_magnitude)
}

/// Refuses a triangle naming a vertex beyond `vertex_count`, or normals (when given) that
/// are not one per vertex: what every tile encoder checks before writing.
pub(crate) fn check_triangles_and_normals<N>(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    normals: Option<&[N]>,
) -> Result<(), EncodeError> {
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(EncodeError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            });
        }
    }
    if let Some(normals) = normals {
        if normals.len() != vertex_count {
            return Err(EncodeError::NormalCount {
                expected: vertex_count,
                got: normals.len(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> GeoRectangle {
        GeoRectangle {
            west: 0.0,
            south: 0.0,
            east: 1.0,
            north: 1.0,
        }
    }

    #[test]
    fn zig_zag_matches_the_spec() {
        assert_eq!(zig_zag(0), 0);
        assert_eq!(zig_zag(-1), 1);
        assert_eq!(zig_zag(1), 2);
        assert_eq!(zig_zag(32767), 65534);
        assert_eq!(zig_zag(-32767), 65533);
    }

    #[test]
    fn oct_encoding_of_the_axes() {
        assert_eq!(oct_encode([0.0, 0.0, 1.0]), [128, 128]);
        assert_eq!(oct_encode([1.0, 0.0, 0.0]), [255, 128]);
        assert_eq!(oct_encode([0.0, 0.0, -1.0]), [255, 255]);
    }

    #[test]
    fn vertices_are_renumbered_by_first_use() {
        let vertices = [[0, 0, 0], [32767, 0, 0], [0, 32767, 0], [32767, 32767, 0]];
        let triangles = [[3, 2, 1], [2, 0, 1]];
        let (order, t) = first_use_order(4, &triangles);
        assert_eq!(order, vec![3, 2, 1, 0]);
        assert_eq!(t, vec![[0, 1, 2], [1, 3, 2]]);
        let bytes = QuantizedMeshTile::new(rect(), 0.0, 1.0, &vertices, &triangles)
            .encode()
            .unwrap();
        // 88 + 4 + 6 * 4 + 4 + 6 * 2 + 4 edges * (4 + 2 * 2) = 164.
        assert_eq!(bytes.len(), 164);
    }

    #[test]
    fn bad_tiles_are_refused() {
        let v = [[0, 0, 40000]];
        let t: [[u32; 3]; 0] = [];
        assert!(matches!(
            QuantizedMeshTile::new(rect(), 0.0, 1.0, &v, &t).encode(),
            Err(EncodeError::ValueOutOfRange { .. })
        ));
        let v = [[0, 0, 0]];
        assert!(matches!(
            QuantizedMeshTile::new(rect(), 0.0, 1.0, &v, &[[0, 0, 1]]).encode(),
            Err(EncodeError::IndexOutOfRange { index: 1, .. })
        ));
        assert!(matches!(
            QuantizedMeshTile::new(rect(), 2.0, 1.0, &v, &t).encode(),
            Err(EncodeError::HeightRange { .. })
        ));
        assert!(matches!(
            QuantizedMeshTile::new(rect(), 0.0, 1.0, &v, &t)
                .with_water_mask(&[0, 255])
                .encode(),
            Err(EncodeError::WaterMaskSize(2))
        ));
    }

    #[test]
    fn the_water_mask_comes_after_the_normals_with_its_length() {
        let vertices = [[0, 0, 0], [32767, 0, 0], [0, 32767, 0]];
        let triangles = [[0, 1, 2]];
        let normals = [[0.0, 0.0, 1.0]; 3];
        let plain = QuantizedMeshTile::new(rect(), 0.0, 1.0, &vertices, &triangles)
            .with_normals(&normals)
            .encode()
            .unwrap();
        let masked = QuantizedMeshTile::new(rect(), 0.0, 1.0, &vertices, &triangles)
            .with_normals(&normals)
            .with_water_mask(&[255])
            .encode()
            .unwrap();
        assert_eq!(masked[..plain.len()], plain[..]);
        assert_eq!(
            masked[plain.len()..],
            [EXTENSION_WATER_MASK, 1, 0, 0, 0, 255]
        );
    }

    #[test]
    fn the_horizon_point_of_a_small_tile_is_above_it() {
        let p = geodetic_to_ecef(10.0, 45.0, 1000.0);
        let hop = horizon_occlusion_point(&[p], p);
        let s = scaled(p);
        let ratio = (hop[0] * hop[0] + hop[1] * hop[1] + hop[2] * hop[2]).sqrt()
            / (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        assert!((ratio - 1.0).abs() < 1e-9, "{ratio}");
    }
}
