//! GeoJSON: a `FeatureCollection` with one `Polygon` Z feature (a closed ring of four
//! positions) per triangle, written as a stream of text and read back with serde, a
//! feature at a time.
//!
//! RFC 7946 coordinates are WGS84 longitude, latitude. A mesh whose EPSG code is 4326 is
//! written that way, with no `crs` member, longitudes wrapped into [-180, 180], and a
//! triangle across the antimeridian as a `MultiPolygon` of its two parts (see
//! [`crate::antimeridian`]); reading rejoins them. Any other CRS is not RFC 7946: the collection then
//! gets the `crs` member of the 2008 GeoJSON specification (which GDAL and QGIS read), a
//! `crs_wkt` member with the full WKT and a `tinsmith_note` saying so. A mesh without a CRS
//! gets `"crs": null`, which the 2008 specification defines as "no CRS".

use std::io::{self, Read, Write};

use serde::de::{DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};
use serde_json::Value;

use crate::antimeridian::{triangle_from_parts, triangle_parts, TriangleParts};
use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};
use crate::weld::Welder;

/// The note written beside a non-WGS84 `crs` member.
const NOTE_SOURCE_CRS: &str = "coordinates are in the CRS named by the crs member (see \
                               crs_wkt), not WGS84 longitude/latitude as RFC 7946 requires";
/// The note written beside `"crs": null`.
const NOTE_NO_CRS: &str =
    "coordinates have no CRS (pixel coordinates, or a raster without a CRS); not RFC 7946";

/// Writes the opening of a `FeatureCollection` up to and including `"features":[`, with
/// the members describing the CRS as explained in the module docs.
pub(crate) fn write_collection_start<W: Write>(
    w: &mut W,
    crs_wkt: Option<&str>,
    epsg: Option<u32>,
) -> io::Result<()> {
    let quote = |text: &str| serde_json::to_string(text).map_err(io::Error::other);
    w.write_all(b"{\"type\":\"FeatureCollection\",\n")?;
    if epsg != Some(4326) {
        let name = match (epsg, crs_wkt) {
            (Some(code), _) => Some(format!("urn:ogc:def:crs:EPSG::{code}")),
            (None, Some(wkt)) => Some(wkt.to_owned()),
            (None, None) => None,
        };
        match name {
            Some(name) => {
                writeln!(
                    w,
                    "\"crs\":{{\"type\":\"name\",\"properties\":{{\"name\":{}}}}},",
                    quote(&name)?
                )?;
                writeln!(w, "\"tinsmith_note\":{},", quote(NOTE_SOURCE_CRS)?)?;
            }
            None => {
                writeln!(w, "\"crs\":null,")?;
                writeln!(w, "\"tinsmith_note\":{},", quote(NOTE_NO_CRS)?)?;
            }
        }
    }
    // RFC 7946 fixes its CRS: a WGS84 WKT would only add an axis order (EPSG:4326's
    // latitude, longitude) that the coordinates do not follow.
    if let (Some(wkt), false) = (crs_wkt, epsg == Some(4326)) {
        writeln!(w, "\"crs_wkt\":{},", quote(wkt)?)?;
    }
    w.write_all(b"\"features\":[\n")
}

/// Writes one position: `[x,y,z]` with the shortest decimals that parse back exactly.
pub(crate) fn write_position<W: Write>(w: &mut W, p: &[f64]) -> io::Result<()> {
    w.write_all(b"[")?;
    for (i, c) in p.iter().enumerate() {
        if i > 0 {
            w.write_all(b",")?;
        }
        write!(w, "{c:?}")?;
    }
    w.write_all(b"]")
}

/// Writes `mesh` as a GeoJSON `FeatureCollection`; each feature has its triangle's
/// position as the `id` property. The caller has checked the mesh.
pub(crate) fn write<W: Write>(mut w: W, mesh: MeshRef<'_>) -> io::Result<()> {
    let crs = mesh.crs_line();
    write_collection_start(&mut w, crs.as_deref(), mesh.epsg)?;
    let rfc7946 = mesh.epsg == Some(4326);
    for (id, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        if id > 0 {
            w.write_all(b",\n")?;
        }
        let corners = [a, b, c].map(|i| mesh.vertices[i as usize]);
        let parts = if rfc7946 {
            triangle_parts(corners)
        } else {
            TriangleParts::Whole(corners)
        };
        let kind = match parts {
            TriangleParts::Whole(_) => "Polygon",
            TriangleParts::Cut(..) => "MultiPolygon",
        };
        write!(w, "{{\"type\":\"Feature\",\"properties\":{{\"id\":{id}")?;
        for attribute in mesh.attributes {
            let name = serde_json::to_string(attribute.name).map_err(io::Error::other)?;
            let mean = crate::mesh::corner_mean(attribute.values, [a, b, c]);
            write!(w, ",{name}:{mean:?}")?;
        }
        write!(w, "}},\"geometry\":{{\"type\":\"{kind}\",\"coordinates\":")?;
        match parts {
            TriangleParts::Whole(corners) => write_ring(&mut w, &corners)?,
            TriangleParts::Cut(west, east) => {
                w.write_all(b"[")?;
                write_ring(&mut w, &west)?;
                w.write_all(b",")?;
                write_ring(&mut w, &east)?;
                w.write_all(b"]")?;
            }
        }
        w.write_all(b"}}")?;
    }
    w.write_all(b"\n]}\n")
}

/// Writes `[[p0, p1, ..., p0]]`: a polygon of one closed ring.
fn write_ring<W: Write>(w: &mut W, ring: &[[f64; 3]]) -> io::Result<()> {
    w.write_all(b"[[")?;
    for (k, p) in ring.iter().chain(&ring[..1]).enumerate() {
        if k > 0 {
            w.write_all(b",")?;
        }
        write_position(w, p)?;
    }
    w.write_all(b"]]")
}

#[derive(Deserialize)]
struct Feature {
    geometry: Option<Geometry>,
}

#[derive(Deserialize)]
struct Geometry {
    #[serde(rename = "type")]
    kind: String,
    #[serde(default)]
    coordinates: Coordinates,
}

/// A `Polygon`'s rings or a `MultiPolygon`'s polygons.
#[derive(Deserialize)]
#[serde(untagged)]
enum Coordinates {
    Polygon(Vec<Vec<Vec<f64>>>),
    MultiPolygon(Vec<Vec<Vec<Vec<f64>>>>),
}

impl Default for Coordinates {
    fn default() -> Coordinates {
        Coordinates::Polygon(Vec::new())
    }
}

/// The positions of a closed ring of 4 (a triangle) or, with `cut`, 4 or 5 (a part of a
/// triangle cut at the antimeridian), without the closing repeat.
fn ring_positions(f: usize, ring: &[Vec<f64>], cut: bool) -> Result<Vec<[f64; 3]>, Problem> {
    let sizes = if cut { 4..=5 } else { 4..=4 };
    if !sizes.contains(&ring.len()) || ring[0] != ring[ring.len() - 1] {
        return Err(Problem::unsupported(format_args!(
            "feature {f} is not a triangle (a closed ring of 4 positions){}: only triangles \
             are read",
            if cut { " cut at the antimeridian" } else { "" }
        )));
    }
    ring[..ring.len() - 1]
        .iter()
        .map(|position| match position.as_slice() {
            &[x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok([x, y, z]),
            [_, _] => Err(Problem::unsupported(format_args!(
                "feature {f} has no heights (2D positions)"
            ))),
            _ => Err(Problem::malformed(format_args!(
                "feature {f} has a position that is not 3 finite numbers"
            ))),
        })
        .collect()
}

/// The EPSG code in a CRS name such as `urn:ogc:def:crs:EPSG::3005` or `EPSG:3005`; 4326
/// for WGS84 longitude, latitude, which OGC calls CRS84 (CRS84h with ellipsoidal heights)
/// and ogr2ogr labels EPSG 4979 when the positions have a z (see [`crate::wgs84_code`]).
fn epsg_of_name(name: &str) -> Option<u32> {
    if name.ends_with("CRS84") || name.ends_with("CRS84h") {
        return Some(4326);
    }
    let upper = name.to_ascii_uppercase();
    let code = upper.strip_prefix("EPSG:").or_else(|| {
        upper
            .strip_prefix("URN:OGC:DEF:CRS:EPSG:")
            .map(|rest| rest.rsplit(':').next().unwrap_or(rest))
    })?;
    code.trim().parse().ok().map(crate::wgs84_code)
}

/// Reads a GeoJSON `FeatureCollection` of triangle `Polygon` Z features (closed rings of
/// four positions), welding equal positions into shared vertices in order of appearance.
///
/// The features are streamed: each is welded into the mesh as it is parsed, so memory is
/// the mesh's, not the text's (a whole parse took about 1.4 times the file).
pub(crate) fn read<R: Read>(r: R) -> Result<Mesh, Problem> {
    let mut collection = Streamed::default();
    let mut deserializer = serde_json::Deserializer::from_reader(r);
    let parsed = CollectionSeed(&mut collection)
        .deserialize(&mut deserializer)
        .and_then(|()| deserializer.end());
    if let Some(problem) = collection.problem.take() {
        return Err(problem);
    }
    parsed.map_err(|e| {
        if e.is_eof() && e.line() == 1 && e.column() == 0 {
            Problem::malformed("the file is empty")
        } else {
            Problem::malformed(e)
        }
    })?;
    match collection.kind.as_deref() {
        Some("FeatureCollection") => {}
        Some(kind) => {
            return Err(Problem::unsupported(format_args!(
                "a {kind} at the top level; only a FeatureCollection is read"
            )))
        }
        None => return Err(Problem::malformed("missing field `type`")),
    }
    let mut mesh = Mesh::default();
    match &collection.crs {
        // RFC 7946: WGS84 longitude, latitude.
        None => mesh.epsg = Some(4326),
        Some(crs) => (mesh.epsg, mesh.crs_wkt) = crs_of(crs)?,
    }
    if collection.crs_wkt.is_some() {
        mesh.crs_wkt = collection.crs_wkt;
    }
    // Triangles cut at the antimeridian were read as WGS84 has them; they are only that in
    // WGS84, which a file without a crs member turns out to be once it has all been read.
    if let Some(f) = collection.first_cut {
        if mesh.epsg != Some(4326) {
            return Err(not_a_triangle(f, "MultiPolygon"));
        }
    }
    if let Some(problem) = collection.cut_problem {
        return Err(problem);
    }
    mesh.vertices = collection.welder.into_vertices();
    mesh.triangles = collection.triangles;
    Ok(mesh)
}

/// The EPSG code, or the name as WKT when it has none, of a `crs` member (`null`: none).
fn crs_of(crs: &Value) -> Result<(Option<u32>, Option<String>), Problem> {
    if crs.is_null() {
        return Ok((None, None));
    }
    let name = crs["properties"]["name"]
        .as_str()
        .ok_or_else(|| Problem::unsupported("a crs member that is not of type `name`"))?;
    Ok(match epsg_of_name(name) {
        Some(code) => (Some(code), None),
        None => (None, Some(name.to_owned())),
    })
}

/// The error for feature `f`, a `kind` geometry that is not read as a triangle.
fn not_a_triangle(f: usize, kind: &str) -> Problem {
    Problem::unsupported(format_args!(
        "feature {f} is a {kind}; only Polygon triangles, MultiPolygons of one triangle and, \
         in WGS84, triangles cut in two at the antimeridian are read"
    ))
}

/// A `FeatureCollection` as it is parsed: its members, and its features welded so far.
#[derive(Default)]
struct Streamed {
    kind: Option<String>,
    /// The `crs` member, when there is one (`null` included).
    crs: Option<Value>,
    /// Whether a `crs` member read so far names another CRS than WGS84 (or none).
    other_crs: bool,
    crs_wkt: Option<String>,
    welder: Welder,
    triangles: Vec<[u32; 3]>,
    /// The first feature that is a triangle cut at the antimeridian (two parts).
    first_cut: Option<usize>,
    /// What the first such feature that spans no triangle fails with.
    cut_problem: Option<Problem>,
    /// The first problem with a feature: parsing stops there.
    problem: Option<Problem>,
}

impl Streamed {
    /// Welds feature `f` into the mesh.
    fn add(&mut self, f: usize, feature: &Feature) -> Result<(), Problem> {
        let Some(geometry) = &feature.geometry else {
            return Err(Problem::malformed(format_args!(
                "feature {f} has no geometry"
            )));
        };
        let corners: [[f64; 3]; 3] = match (geometry.kind.as_str(), &geometry.coordinates) {
            ("Polygon", Coordinates::Polygon(rings)) => {
                let ring = match rings.as_slice() {
                    [ring] => ring,
                    rings => {
                        return Err(Problem::unsupported(format_args!(
                            "feature {f} has {} rings; only triangles (one ring) are read",
                            rings.len()
                        )))
                    }
                };
                let positions = ring_positions(f, ring, false)?;
                [positions[0], positions[1], positions[2]]
            }
            // A MultiPolygon of one triangle (as ogr2ogr -nlt MULTIPOLYGON writes them).
            ("MultiPolygon", Coordinates::MultiPolygon(polygons))
                if polygons.len() == 1 && polygons[0].len() == 1 =>
            {
                let positions = ring_positions(f, &polygons[0][0], false)?;
                [positions[0], positions[1], positions[2]]
            }
            ("MultiPolygon", Coordinates::MultiPolygon(polygons)) if !self.other_crs => {
                self.first_cut.get_or_insert(f);
                match cut_triangle(f, polygons) {
                    Ok(corners) => corners,
                    Err(problem) => {
                        self.cut_problem.get_or_insert(problem);
                        return Ok(());
                    }
                }
            }
            (kind, _) => return Err(not_a_triangle(f, kind)),
        };
        let mut triangle = [0u32; 3];
        for (index, p) in triangle.iter_mut().zip(corners) {
            *index = self
                .welder
                .vertex(p)
                .ok_or_else(|| Problem::unsupported("more than 2^32 vertices"))?;
        }
        self.triangles.push(triangle);
        Ok(())
    }
}

/// The triangle whose two parts, cut at the antimeridian, are feature `f`'s polygons.
fn cut_triangle(f: usize, polygons: &[Vec<Vec<Vec<f64>>>]) -> Result<[[f64; 3]; 3], Problem> {
    let parts = match polygons {
        [west, east] if west.len() == 1 && east.len() == 1 => [
            ring_positions(f, &west[0], true)?,
            ring_positions(f, &east[0], true)?,
        ],
        _ => {
            return Err(Problem::unsupported(format_args!(
                "feature {f} is a MultiPolygon other than a triangle cut in two at the \
                 antimeridian"
            )))
        }
    };
    triangle_from_parts(&[&parts[0], &parts[1]]).ok_or_else(|| {
        Problem::malformed(format_args!("feature {f}: its two parts span no triangle"))
    })
}

/// Parses a `FeatureCollection` object into a [`Streamed`].
struct CollectionSeed<'s>(&'s mut Streamed);

impl<'de> DeserializeSeed<'de> for CollectionSeed<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        deserializer.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for CollectionSeed<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a GeoJSON object")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "type" => self.0.kind = Some(map.next_value()?),
                "crs" => {
                    let crs: Value = map.next_value()?;
                    // A crs member that names no CRS fails once the file is read.
                    self.0.other_crs = crs_of(&crs).is_ok_and(|(epsg, _)| epsg != Some(4326));
                    self.0.crs = Some(crs);
                }
                "crs_wkt" => self.0.crs_wkt = map.next_value()?,
                "features" => map.next_value_seed(FeaturesSeed(&mut *self.0))?,
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(())
    }
}

/// Parses the `features` array, welding each feature as it comes.
struct FeaturesSeed<'s>(&'s mut Streamed);

impl<'de> DeserializeSeed<'de> for FeaturesSeed<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        deserializer.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for FeaturesSeed<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("an array of features")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut f = 0;
        while let Some(feature) = seq.next_element::<Feature>()? {
            if let Err(problem) = self.0.add(f, &feature) {
                self.0.problem = Some(problem);
                return Err(serde::de::Error::custom("stopped at a feature"));
            }
            f += 1;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::antimeridian::wrap_longitude;

    fn write_to_string(mesh: MeshRef<'_>) -> String {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh).expect("writing to a Vec");
        String::from_utf8(bytes).expect("GeoJSON is text")
    }

    const VERTICES: [[f64; 3]; 4] = [
        [-123.123_456_789_012_34, 49.0, 10.25],
        [-123.0, 49.000_000_000_000_01, 11.0],
        [-123.0, 49.1, 0.1 + 0.2],
        [-123.1, 49.1, -0.0],
    ];
    const TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

    #[test]
    fn wgs84_is_plain_rfc7946_and_round_trips_exactly() -> Result<(), Problem> {
        let text = write_to_string(MeshRef::new(&VERTICES, &TRIANGLES).with_epsg(4326));
        let value: Value = serde_json::from_str(&text).expect("valid JSON");
        assert!(value.get("crs").is_none());
        assert_eq!(value["features"].as_array().map(Vec::len), Some(2));
        assert_eq!(value["features"][1]["properties"]["id"], 1);
        let mesh = read(text.as_bytes())?;
        assert_eq!(mesh.vertices, VERTICES);
        assert_eq!(mesh.triangles, TRIANGLES);
        assert_eq!((mesh.epsg, mesh.crs_wkt), (Some(4326), None));
        Ok(())
    }

    #[test]
    fn wgs84_gets_no_crs_wkt_whose_axes_it_does_not_follow() {
        // EPSG:4326's WKT declares latitude, longitude; RFC 7946 positions are longitude,
        // latitude. It was written beside them (a 4326 raster with --geojson-source-crs).
        let wkt = "GEOGCS[\"WGS 84\",AXIS[\"Latitude\",NORTH],AXIS[\"Longitude\",EAST],\
                   AUTHORITY[\"EPSG\",\"4326\"]]";
        let text = write_to_string(
            MeshRef::new(&VERTICES, &TRIANGLES)
                .with_crs_wkt(wkt)
                .with_epsg(4326),
        );
        let value: Value = serde_json::from_str(&text).expect("valid JSON");
        assert!(value.get("crs_wkt").is_none(), "{text}");
        assert!(value.get("crs").is_none());
    }

    #[test]
    fn wgs84_triangles_across_180_are_cut_and_read_back_welded() -> Result<(), Problem> {
        // A strip of four triangles on 0..360 longitudes around 180, a vertex on it.
        let vertices = [
            [179.0, 0.0, 1.0],
            [180.0, 0.0, 2.0],
            [181.0, 0.0, 3.0],
            [179.0, 1.0, 4.0],
            [180.0, 1.0, 5.0],
            [181.0, 1.0, 6.0],
        ];
        let triangles = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let mut cut = vertices;
        cut[1][0] = 180.5; // so the first triangle crosses 180; the others touch it or not
        let text = write_to_string(MeshRef::new(&cut, &triangles).with_epsg(4326));
        let value: Value = serde_json::from_str(&text).expect("valid JSON");
        let kinds: Vec<&str> = value["features"]
            .as_array()
            .expect("features")
            .iter()
            .map(|f| f["geometry"]["type"].as_str().expect("type"))
            .collect();
        assert_eq!(kinds, ["MultiPolygon", "Polygon", "Polygon", "Polygon"]);
        for f in value["features"].as_array().expect("features") {
            let text = f["geometry"]["coordinates"].to_string();
            assert!(!text.contains("181") && !text.contains("180.5"), "{text}");
        }
        let mesh = read(text.as_bytes())?;
        assert_eq!(mesh.triangles.len(), 4);
        // The vertex on 180 is -180 in the triangle east of it: two positions for one
        // vertex, as RFC 7946 has it (`tinsmith verify` rejoins them on the raster).
        assert_eq!(mesh.vertices.len(), 7, "{:?}", mesh.vertices);
        // Every triangle comes back with its corners (longitudes wrapped), in order.
        for (t, read) in triangles.iter().zip(&mesh.triangles) {
            let want = t.map(|i| [wrap_longitude(cut[i as usize][0]), cut[i as usize][1]]);
            let got = read.map(|i| [mesh.vertices[i as usize][0], mesh.vertices[i as usize][1]]);
            // The same place: 180 and -180 are one meridian.
            let same = |a: [f64; 2], b: [f64; 2]| {
                a[1] == b[1] && (a[0] == b[0] || (a[0] - b[0]).abs() == 360.0)
            };
            assert!(
                (0..3).any(|r| (0..3).all(|k| same(got[(k + r) % 3], want[k]))),
                "{got:?}"
            );
        }

        // The vertices on 180 are written as 180 or -180 by the side of their triangle.
        let text = write_to_string(MeshRef::new(&vertices, &triangles).with_epsg(4326));
        assert!(text.contains("[-180.0,0.0,2.0]") && text.contains("[180.0,0.0,2.0]"));
        assert!(!text.contains("MultiPolygon"));

        // Only in WGS84: elsewhere coordinates are written as they are.
        let text = write_to_string(MeshRef::new(&cut, &triangles).with_epsg(32660));
        assert!(!text.contains("MultiPolygon") && text.contains("181"));
        Ok(())
    }

    #[test]
    fn members_are_read_in_any_order_and_cut_triangles_only_in_wgs84() -> Result<(), Problem> {
        // The features are welded as they are parsed: a crs member after them still
        // decides whether a triangle cut at the antimeridian is one.
        let vertices = [[179.0, 0.0, 1.0], [181.0, 0.0, 2.0], [179.0, 1.0, 3.0]];
        let text = write_to_string(MeshRef::new(&vertices, &[[0, 1, 2]]).with_epsg(4326));
        let mut value: Value = serde_json::from_str(&text).expect("valid JSON");
        let features = value["features"].take();
        assert_eq!(features[0]["geometry"]["type"], "MultiPolygon");
        let before = read(text.as_bytes())?;
        for crs in [
            "",
            ",\"crs\":null",
            ",\"crs\":{\"type\":\"name\",\"properties\":{\"name\":\"EPSG:32660\"}}",
        ] {
            for features_first in [true, false] {
                let text = if features_first {
                    format!("{{\"features\":{features}{crs},\"type\":\"FeatureCollection\"}}")
                } else {
                    format!("{{\"type\":\"FeatureCollection\"{crs},\"features\":{features}}}")
                };
                match read(text.as_bytes()) {
                    Ok(mesh) if crs.is_empty() => {
                        assert_eq!(mesh.vertices, before.vertices);
                        assert_eq!(mesh.triangles, before.triangles);
                    }
                    Err(Problem::Unsupported(reason)) if !crs.is_empty() => {
                        assert!(reason.contains("feature 0 is a MultiPolygon"), "{reason}");
                    }
                    other => panic!("{text}: {other:?}"),
                }
            }
        }
        Ok(())
    }

    #[test]
    fn source_crs_gets_a_crs_member_and_a_note() -> Result<(), Problem> {
        let wkt = "PROJCS[\"NAD83 / BC Albers\",AUTHORITY[\"EPSG\",\"3005\"]]";
        let text = write_to_string(
            MeshRef::new(&VERTICES, &TRIANGLES)
                .with_crs_wkt(wkt)
                .with_epsg(3005),
        );
        let value: Value = serde_json::from_str(&text).expect("valid JSON");
        assert_eq!(
            value["crs"]["properties"]["name"],
            "urn:ogc:def:crs:EPSG::3005"
        );
        assert!(value["tinsmith_note"].as_str().is_some());
        let mesh = read(text.as_bytes())?;
        assert_eq!(
            (mesh.epsg, mesh.crs_wkt.as_deref()),
            (Some(3005), Some(wkt))
        );

        let text =
            write_to_string(MeshRef::new(&VERTICES, &TRIANGLES).with_crs_wkt("LOCAL_CS[\"x\"]"));
        let mesh = read(text.as_bytes())?;
        assert_eq!(
            (mesh.epsg, mesh.crs_wkt.as_deref()),
            (None, Some("LOCAL_CS[\"x\"]"))
        );

        let text = write_to_string(MeshRef::new(&VERTICES, &TRIANGLES));
        assert!(text.contains("\"crs\":null"));
        let mesh = read(text.as_bytes())?;
        assert_eq!((mesh.epsg, mesh.crs_wkt), (None, None));
        Ok(())
    }

    #[test]
    fn crs_names() {
        assert_eq!(epsg_of_name("urn:ogc:def:crs:EPSG::3005"), Some(3005));
        assert_eq!(
            epsg_of_name("urn:ogc:def:crs:EPSG:9.8.1:32633"),
            Some(32633)
        );
        assert_eq!(epsg_of_name("EPSG:2056"), Some(2056));
        assert_eq!(epsg_of_name("urn:ogc:def:crs:OGC:1.3:CRS84"), Some(4326));
        // ogr2ogr's label for WGS84 positions with a z, and OGC's.
        assert_eq!(epsg_of_name("urn:ogc:def:crs:EPSG::4979"), Some(4326));
        assert_eq!(epsg_of_name("urn:ogc:def:crs:OGC::CRS84h"), Some(4326));
        assert_eq!(epsg_of_name("PROJCS[\"x\"]"), None);
    }

    #[test]
    fn bad_files_are_reported() {
        let cases: [(&str, &str); 8] = [
            ("", "empty"),
            ("{\"type\":\"Feature\"}", "only a FeatureCollection"),
            ("{\"type\":\"FeatureCollection\",\"features\":[{\"geometry\":null}]}", "no geometry"),
            (
                "{\"type\":\"FeatureCollection\",\"features\":[{\"geometry\":{\"type\":\"Point\",\"coordinates\":[]}}]}",
                "only Polygon",
            ),
            (
                "{\"type\":\"FeatureCollection\",\"features\":[{\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[[0,0,0],[1,0,0],[1,1,0],[0,1,0],[0,0,0]]]}}]}",
                "only triangles",
            ),
            (
                "{\"type\":\"FeatureCollection\",\"features\":[{\"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[[0,0],[1,0],[1,1],[0,0]]]}}]}",
                "no heights",
            ),
            ("{\"type\":\"FeatureCollection\",\"features\":[", "EOF"),
            ("{\"type\":\"FeatureCollection\",\"crs\":{\"type\":\"link\"}}", "type `name`"),
        ];
        for (text, expected) in cases {
            match read(text.as_bytes()) {
                Err(Problem::Malformed(reason) | Problem::Unsupported(reason)) => {
                    assert!(reason.contains(expected), "{text}: {reason}");
                }
                other => panic!("{text}: {other:?}"),
            }
        }
    }
}
