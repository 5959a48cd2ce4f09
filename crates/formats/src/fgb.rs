//! FlatGeobuf through the `flatgeobuf` crate: one `Polygon` Z feature (a closed ring of 4)
//! per triangle, an `id` column, the CRS in the header, a packed Hilbert R-tree index.
//!
//! With the index, the writer sorts features along a Hilbert curve, so the file's feature
//! order is not the mesh's; the `id` column (`Long`: GDAL reads unsigned 64-bit columns as
//! reals) holds each triangle's position and the reader puts them back in that order.
//! `Polygon` rather than `Triangle`, `PolyhedralSurface` or `TIN`: GDAL reads all of them,
//! but pyogrio (geopandas' default engine) and the flatgeobuf JavaScript reader (web maps)
//! read no `Triangle`. Files of `Triangle` features, as tinsmith wrote before, are read.

use std::cell::Cell;
use std::io::{self, Read, Write};
use std::rc::Rc;

use flatgeobuf::geozero::{ColumnValue, FeatureProcessor, GeomProcessor, PropertyProcessor};
use flatgeobuf::{
    ColumnType, FallibleStreamingIterator, FgbCrs, FgbFeature, FgbReader, FgbWriter,
    FgbWriterOptions, Geometry, GeometryType,
};

use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};
use crate::weld::Welder;

/// Name of the triangle-position column.
const ID: &str = "id";

/// The header CRS for a WKT and EPSG code.
pub(crate) fn crs<'a>(wkt: Option<&'a str>, epsg: Option<u32>) -> FgbCrs<'a> {
    FgbCrs {
        org: epsg.map(|_| "EPSG"),
        code: epsg.and_then(|c| i32::try_from(c).ok()).unwrap_or(0),
        wkt,
        ..FgbCrs::default()
    }
}

/// A flatgeobuf or geozero error as an I/O error for the atomic writer: the I/O error
/// inside it when there is one (a broken pipe, a full disk), so that its kind survives.
pub(crate) fn io_error(error: impl std::error::Error + Send + Sync + 'static) -> io::Error {
    let boxed: Box<dyn std::error::Error + Send + Sync> = Box::new(error);
    let boxed = match boxed.downcast::<flatgeobuf::Error>() {
        Ok(error) => match *error {
            flatgeobuf::Error::IO(io) => return io,
            other => Box::new(other),
        },
        Err(other) => other,
    };
    match boxed.downcast::<geozero::error::GeozeroError>() {
        Ok(error) => match *error {
            geozero::error::GeozeroError::IoError(io) => io,
            other => io::Error::other(other),
        },
        Err(other) => io::Error::other(other),
    }
}

/// Writes `mesh` as FlatGeobuf. The writer keeps the features in an anonymous temporary
/// file until the index is built, so memory holds only one index entry per triangle.
pub(crate) fn write<W: Write>(w: W, mesh: MeshRef<'_>) -> io::Result<()> {
    let wkt = mesh.crs_line();
    let options = FgbWriterOptions {
        write_index: true,
        detect_type: false,
        promote_to_multi: false,
        has_z: true,
        crs: crs(wkt.as_deref(), mesh.epsg),
        description: Some("TIN triangles written by tinsmith; id = triangle position"),
        ..FgbWriterOptions::default()
    };
    let mut fgb =
        FgbWriter::create_with_options("tin", GeometryType::Polygon, options).map_err(io_error)?;
    fgb.add_column(ID, ColumnType::Long, |_, _| {});
    for attribute in mesh.attributes {
        fgb.add_column(attribute.name, ColumnType::Double, |_, _| {});
    }
    for (id, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        let id64 = id as u64;
        fgb.property(0, ID, &ColumnValue::Long(id as i64))
            .map_err(io_error)?;
        for (k, attribute) in mesh.attributes.iter().enumerate() {
            let mean = crate::mesh::corner_mean(attribute.values, [a, b, c]);
            fgb.property(k + 1, attribute.name, &ColumnValue::Double(mean))
                .map_err(io_error)?;
        }
        fgb.polygon_begin(true, 1, 0).map_err(io_error)?;
        fgb.linestring_begin(false, 4, 0).map_err(io_error)?;
        for (k, i) in [a, b, c, a].into_iter().enumerate() {
            let [x, y, z] = mesh.vertices[i as usize];
            fgb.coordinate(x, y, Some(z), None, None, None, k)
                .map_err(io_error)?;
        }
        fgb.linestring_end(false, 0).map_err(io_error)?;
        fgb.polygon_end(true, 0).map_err(io_error)?;
        fgb.feature_end(id64).map_err(io_error)?;
    }
    fgb.write(w).map_err(io_error)
}

/// The first three corners of a triangle geometry's single ring.
fn corners(geometry: &Geometry<'_>, feature: usize) -> Result<[[f64; 3]; 3], Problem> {
    let bad = |what: &str| Problem::malformed(format_args!("feature {feature}: {what}"));
    let xy = geometry.xy().ok_or_else(|| bad("no coordinates"))?;
    let z = geometry
        .z()
        .ok_or_else(|| Problem::unsupported(format_args!("feature {feature} has no heights")))?;
    let points = xy.len() / 2;
    if !(points == 3 || points == 4)
        || z.len() != points
        || geometry.ends().is_some_and(|e| e.len() > 1)
    {
        return Err(Problem::unsupported(format_args!(
            "feature {feature} is not a triangle (one ring of 3 or 4 positions): only \
             triangles are read"
        )));
    }
    let mut out = [[0.0; 3]; 3];
    for (k, p) in out.iter_mut().enumerate() {
        *p = [xy.get(2 * k), xy.get(2 * k + 1), z.get(k)];
        if !p.iter().all(|c| c.is_finite()) {
            return Err(bad("a non-finite coordinate"));
        }
    }
    if points == 4 && [xy.get(6), xy.get(7), z.get(3)] != out[0] {
        return Err(Problem::unsupported(format_args!(
            "feature {feature} is not a triangle (its ring of 4 positions does not close: \
             the last is not the first)"
        )));
    }
    Ok(out)
}

/// Reads a FlatGeobuf file of `Triangle`, `Polygon` (one ring) or `TIN` features with Z,
/// welding equal positions into shared vertices; when every feature has an `id`, the
/// triangles are put in `id` order.
pub(crate) fn read<R: Read>(r: R) -> Result<Mesh, Problem> {
    let frames = Rc::new(Frames::default());
    let framed = Framed {
        inner: r,
        frames: Rc::clone(&frames),
        feature: Vec::new(),
        passed: 0,
    };
    let reader = FgbReader::open(framed).map_err(Problem::malformed)?;
    let header = reader.header();
    let index = index_size(header.features_count(), header.index_node_size())
        .and_then(|index| frames.position.get().checked_add(index))
        .ok_or_else(|| {
            Problem::malformed(format_args!(
                "no index of {} features in nodes of {} fits in a file",
                header.features_count(),
                header.index_node_size()
            ))
        })?;
    frames.features_at.set(Some(index));
    let mut mesh = Mesh::default();
    if let Some(crs) = header.crs() {
        mesh.epsg = u32::try_from(crs.code())
            .ok()
            .filter(|&c| c > 0)
            .map(crate::wgs84_code);
        mesh.crs_wkt = crs.wkt().map(str::to_owned).filter(|w| !w.is_empty());
    }
    // 0 means "not known" (a writer that streamed without counting).
    let declared = header.features_count();
    let kind = header.geometry_type();
    if !matches!(
        kind,
        GeometryType::Triangle
            | GeometryType::Polygon
            | GeometryType::MultiPolygon
            | GeometryType::TIN
            | GeometryType::Unknown
    ) {
        return Err(Problem::unsupported(format_args!(
            "{kind:?} geometries; only Triangle, Polygon, MultiPolygon and TIN are read"
        )));
    }
    let columns: Vec<(ColumnType, bool)> = header
        .columns()
        .map(|columns| {
            columns
                .iter()
                .map(|c| (c.type_(), c.name() == ID))
                .collect()
        })
        .unwrap_or_default();
    let mut features = reader.select_all_seq().map_err(Problem::malformed)?;
    let mut welder = Welder::default();
    let mut ids: Vec<Option<i64>> = Vec::new();
    let mut feature_number = 0usize;
    while let Some(feature) = features.next().map_err(Problem::malformed)? {
        let geometry = feature.geometry().ok_or_else(|| {
            Problem::malformed(format_args!("feature {feature_number} has no geometry"))
        })?;
        let id = feature_id(feature, &columns, feature_number)?;
        let mut triangles = Vec::new();
        match geometry.parts() {
            Some(parts) => {
                for part in parts.iter() {
                    triangles.push(corners(&part, feature_number)?);
                }
            }
            None => triangles.push(corners(&geometry, feature_number)?),
        }
        for corners in triangles {
            let mut triangle = [0u32; 3];
            for (index, p) in triangle.iter_mut().zip(corners) {
                *index = welder
                    .vertex(p)
                    .ok_or_else(|| Problem::unsupported("more than 2^32 vertices"))?;
            }
            mesh.triangles.push(triangle);
            ids.push(id);
        }
        feature_number += 1;
    }
    drop(features);
    if frames.truncated.get() {
        return Err(Problem::malformed(format_args!(
            "the file ends inside feature {feature_number} (truncated)"
        )));
    }
    if declared > 0 && feature_number as u64 != declared {
        return Err(Problem::malformed(format_args!(
            "the header declares {declared} features and {feature_number} were read (a \
             truncated or damaged file)"
        )));
    }
    mesh.vertices = welder.into_vertices();
    if ids.iter().all(Option::is_some) {
        let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
        order.sort_by_key(|&i| ids[i]);
        mesh.triangles = order.into_iter().map(|i| mesh.triangles[i]).collect();
        // Vertices follow the triangles' order, as the other readers give them.
        let mut welder = Welder::default();
        let vertices = std::mem::take(&mut mesh.vertices);
        for triangle in &mut mesh.triangles {
            for index in triangle.iter_mut() {
                *index = welder
                    .vertex(vertices[*index as usize])
                    .ok_or_else(|| Problem::unsupported("more than 2^32 vertices"))?;
            }
        }
        mesh.vertices = welder.into_vertices();
    }
    Ok(mesh)
}

/// The feature's `id` (a `Long` column), read from its property bytes with every length
/// checked: the `flatgeobuf` crate reads them unchecked and panics on a value cut short.
/// `None` when the feature has no `id` of that type, or has columns the crate cannot read.
/// `columns` are the header's column types, each with whether it is the `id` column.
fn feature_id(
    feature: &FgbFeature,
    columns: &[(ColumnType, bool)],
    number: usize,
) -> Result<Option<i64>, Problem> {
    let Some(properties) = feature.fbs_feature().properties() else {
        return Ok(None);
    };
    let bytes = properties.bytes();
    let short = || {
        Problem::malformed(format_args!(
            "feature {number}: its properties end inside a value"
        ))
    };
    let mut at = 0usize;
    while at + 1 < bytes.len() {
        let column = usize::from(u16::from_le_bytes([bytes[at], bytes[at + 1]]));
        at += 2;
        if column >= columns.len() {
            return Ok(None);
        }
        let (kind, is_id) = columns[column];
        let size = match kind {
            ColumnType::Byte | ColumnType::UByte | ColumnType::Bool => 1,
            ColumnType::Short | ColumnType::UShort => 2,
            ColumnType::Int | ColumnType::UInt | ColumnType::Float => 4,
            ColumnType::Long | ColumnType::ULong | ColumnType::Double => 8,
            ColumnType::String | ColumnType::Json | ColumnType::DateTime | ColumnType::Binary => {
                let len = bytes.get(at..at + 4).ok_or_else(short)?;
                at += 4;
                u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize
            }
            _ => return Ok(None),
        };
        let value = at
            .checked_add(size)
            .and_then(|end| bytes.get(at..end))
            .ok_or_else(short)?;
        if is_id && kind == ColumnType::Long {
            let mut raw = [0u8; 8];
            raw.copy_from_slice(value);
            return Ok(Some(i64::from_le_bytes(raw)));
        }
        at += size;
    }
    Ok(None)
}

/// Bytes of the packed R-tree index of `features` items in nodes of `node_size` items, as
/// the `flatgeobuf` crate computes it (0 for none); `None` when that overflows or for nodes
/// of 1 item, which the crate cannot index.
fn index_size(features: u64, node_size: u16) -> Option<u64> {
    /// Bytes of one node: a bounding box and an offset.
    const NODE_BYTES: u64 = 40;
    if features == 0 || node_size == 0 {
        return Some(0);
    }
    if node_size == 1 {
        return None;
    }
    let (mut level, mut nodes) = (features, features);
    loop {
        level = level.div_ceil(u64::from(node_size));
        nodes = nodes.checked_add(level)?;
        if level == 1 {
            return nodes.checked_mul(NODE_BYTES);
        }
    }
}

/// What a [`Framed`] reader shares with the function that handed it to `flatgeobuf`.
#[derive(Debug, Default)]
struct Frames {
    /// Bytes passed on so far.
    position: Cell<u64>,
    /// Where the first feature's length prefix is, once the header is known.
    features_at: Cell<Option<u64>>,
    /// Whether the input ended inside a feature or its length prefix.
    truncated: Cell<bool>,
}

/// The input as the `flatgeobuf` crate reads it, except that a feature's length prefix is
/// passed on only once all the bytes it announces have arrived: the crate sizes a buffer
/// by the prefix before reading, so a few bytes announcing a 4 GB feature would otherwise
/// allocate 4 GB. A feature cut short ends the features with [`Frames::truncated`] set.
struct Framed<R> {
    inner: R,
    frames: Rc<Frames>,
    /// The current feature, length prefix included.
    feature: Vec<u8>,
    /// How much of `feature` was passed on.
    passed: usize,
}

impl<R: Read> Read for Framed<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let position = self.frames.position.get();
        let n = match self.frames.features_at.get() {
            Some(at) if position >= at => self.read_feature(buf)?,
            at => {
                let before = at.map_or(u64::MAX, |at| at - position);
                let len = usize::try_from(before).map_or(buf.len(), |b| b.min(buf.len()));
                self.inner.read(&mut buf[..len])?
            }
        };
        self.frames.position.set(position + n as u64);
        Ok(n)
    }
}

impl<R: Read> Framed<R> {
    /// Passes on the current feature, after reading the next one whole when it is done.
    fn read_feature(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.passed == self.feature.len() {
            self.feature.clear();
            self.passed = 0;
            let prefix = (&mut self.inner).take(4).read_to_end(&mut self.feature)?;
            if prefix == 0 {
                return Ok(0);
            }
            let len = match self.feature[..] {
                [a, b, c, d] => u32::from_le_bytes([a, b, c, d]),
                _ => 0,
            };
            // Grows as the bytes arrive, never beyond them.
            (&mut self.inner)
                .take(u64::from(len))
                .read_to_end(&mut self.feature)?;
            if prefix < 4 || self.feature.len() - 4 < len as usize {
                self.frames.truncated.set(true);
                return Err(io::ErrorKind::UnexpectedEof.into());
            }
        }
        let n = buf.len().min(self.feature.len() - self.passed);
        buf[..n].copy_from_slice(&self.feature[self.passed..self.passed + n]);
        self.passed += n;
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_to_vec(mesh: MeshRef<'_>) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh).expect("writing to a Vec");
        bytes
    }

    #[test]
    fn a_file_cut_at_a_feature_boundary_is_refused() {
        let vertices = [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 2.0],
            [0.0, 1.0, 3.0],
            [1.0, 1.0, 4.0],
        ];
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let bytes = write_to_vec(MeshRef::new(&vertices, &triangles));
        assert_eq!(read(&bytes[..]).unwrap().triangles.len(), 2);
        // Drop the last feature: every cut that still parses must be refused.
        let cut = (1..bytes.len()).filter(|&n| match read(&bytes[..n]) {
            Ok(mesh) => panic!("{n} of {} bytes read as {mesh:?}", bytes.len()),
            Err(problem) => format!("{problem:?}").contains("features and"),
        });
        assert!(cut.count() > 0, "no cut reached the feature count check");
    }

    #[test]
    fn round_trip_restores_order_and_crs() -> Result<(), Problem> {
        // A strip of triangles far apart, so the Hilbert sort reorders them.
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..50u32 {
            let x = f64::from((i * 37) % 50) * 100.0 + 500_000.123_456_789;
            vertices.extend([
                [x, 0.5, 1.0 / 3.0],
                [x + 1.0, 0.5, 2.0],
                [x, 1.5, f64::from(i)],
            ]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let bytes = write_to_vec(
            MeshRef::new(&vertices, &triangles)
                .with_crs_wkt("PROJCS[\"x\"]")
                .with_epsg(32610),
        );
        let mesh = read(bytes.as_slice())?;
        assert_eq!(mesh.vertices, vertices);
        assert_eq!(mesh.triangles, triangles);
        assert_eq!(mesh.epsg, Some(32610));
        assert_eq!(mesh.crs_wkt.as_deref(), Some("PROJCS[\"x\"]"));
        Ok(())
    }

    #[test]
    fn a_ring_that_does_not_close_is_refused() {
        // The closing position differs from the first in x, then in z: GDAL warns "Non
        // closed ring detected"; the reader took the first three and said nothing.
        let vertices = [[0.25, 0.75, 7.0], [0.0, 0.0, 1.0], [1.0, 0.0, 2.0]];
        let bytes = write_to_vec(MeshRef::new(&vertices, &[[0, 1, 2]]));
        assert_eq!(read(&bytes[..]).unwrap().triangles.len(), 1);
        for (old, new) in [(0.25f64, 0.5f64), (7.0, 8.0)] {
            let (old, new) = (old.to_le_bytes(), new.to_le_bytes());
            let at = bytes
                .windows(8)
                .rposition(|w| w == old)
                .expect("closing value");
            let mut open = bytes.clone();
            open[at..at + 8].copy_from_slice(&new);
            let problem = read(&open[..]).expect_err("an open ring");
            assert!(
                format!("{problem:?}").contains("does not close"),
                "{problem:?}"
            );
        }
    }

    #[test]
    fn polygons_are_written_and_triangles_as_written_before_are_read() -> Result<(), Problem> {
        let vertices = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]];
        let bytes = write_to_vec(MeshRef::new(&vertices, &[[0, 1, 2]]));
        let header = FgbReader::open(&bytes[..]).map_err(io_error)?;
        assert_eq!(header.header().geometry_type(), GeometryType::Polygon);
        // tinsmith's files before: `Triangle` features.
        let options = FgbWriterOptions {
            write_index: false,
            detect_type: false,
            has_z: true,
            ..FgbWriterOptions::default()
        };
        let mut fgb = FgbWriter::create_with_options("tin", GeometryType::Triangle, options)
            .map_err(io_error)?;
        fgb.add_column(ID, ColumnType::Long, |_, _| {});
        fgb.property(0, ID, &ColumnValue::Long(0))
            .map_err(io_error)?;
        fgb.triangle_begin(true, 1, 0).map_err(io_error)?;
        fgb.linestring_begin(false, 4, 0).map_err(io_error)?;
        for (k, [x, y, z]) in [0, 1, 2, 0].map(|i| vertices[i]).into_iter().enumerate() {
            fgb.coordinate(x, y, Some(z), None, None, None, k)
                .map_err(io_error)?;
        }
        fgb.linestring_end(false, 0).map_err(io_error)?;
        fgb.triangle_end(true, 0).map_err(io_error)?;
        fgb.feature_end(0).map_err(io_error)?;
        let mut old = Vec::new();
        fgb.write(&mut old).map_err(io_error)?;
        let mesh = read(&old[..])?;
        assert_eq!(mesh.vertices, vertices);
        assert_eq!(mesh.triangles, [[0, 1, 2]]);
        Ok(())
    }

    #[test]
    fn a_feature_longer_than_the_file_is_refused_before_it_is_allocated() {
        let vertices = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]];
        let mut bytes = write_to_vec(MeshRef::new(&vertices, &[[0, 1, 2]]));
        // Magic, header length and header, then the index of one feature (2 nodes).
        let header = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
        let feature = 12 + header + 80;
        bytes[feature..feature + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
        let problem = read(bytes.as_slice()).expect_err("a 4 GB feature in a small file");
        assert!(
            format!("{problem:?}").contains("ends inside feature 0 (truncated)"),
            "{problem:?}"
        );
    }

    #[test]
    fn index_sizes_match_the_crate_and_overflow_is_refused() {
        for (features, node_size) in [(1, 16), (2, 2), (1000, 16), (70_000, 3)] {
            assert_eq!(
                index_size(features, node_size),
                Some(flatgeobuf::packed_r_tree::PackedRTree::index_size(
                    features as usize,
                    node_size
                ) as u64)
            );
        }
        assert_eq!(index_size(0, 16), Some(0));
        assert_eq!(index_size(5, 0), Some(0));
        assert_eq!(index_size(5, 1), None);
        assert_eq!(index_size(u64::MAX, 2), None);
    }

    #[test]
    fn empty_mesh_and_garbage() -> Result<(), Problem> {
        let bytes = write_to_vec(MeshRef::new(&[], &[]));
        let mesh = read(bytes.as_slice())?;
        assert!(mesh.triangles.is_empty() && mesh.vertices.is_empty());
        assert!(read(&b""[..]).is_err());
        assert!(read(&b"fgb\x03fgb\x00garbage"[..]).is_err());
        let good = write_to_vec(MeshRef::new(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]],
            &[[0, 1, 2]],
        ));
        for cut in 0..good.len() {
            let _ = read(&good[..cut]);
        }
        Ok(())
    }
}
