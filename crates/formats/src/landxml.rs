//! LandXML 1.2: a TIN `Surface` as civil-engineering software (Civil 3D, 12d) imports it.
//!
//! ```xml
//! <LandXML version="1.2" date="1970-01-01" time="00:00:00" ...>
//!   <Units><Metric linearUnit="meter" .../></Units>
//!   <CoordinateSystem name="NAD83 / BC Albers" epsgCode="3005" ogcWktCode="PROJCS[...]"/>
//!   <Application name="tinsmith" .../>
//!   <Surfaces><Surface name="tin"><Definition surfType="TIN" elevMin=".." elevMax="..">
//!     <Pnts><P id="1">northing easting elevation</P>...</Pnts>
//!     <Faces><F>1 2 3</F>...</Faces>
//!   </Definition></Surface></Surfaces>
//! </LandXML>
//! ```
//! Points are written **northing easting elevation** (y x z), as LandXML orders them, with
//! 1-based ids; faces keep the mesh's orientation. `date` and `time` are required by the
//! schema; tinsmith writes the epoch so that the same mesh gives the same bytes.

use std::collections::HashMap;
use std::io::{self, BufRead, Write};

use quick_xml::events::{BytesStart, Event};

use crate::error::Problem;
use crate::mesh::{Mesh, MeshRef};

/// Most nested elements accepted while reading; guards against pathological files.
const MAX_DEPTH: usize = 256;

/// `text` with the five XML special characters escaped, for attribute values.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// The CRS name: the first quoted string of the WKT (`PROJCS["NAD83 / BC Albers", ...`).
fn crs_name(wkt: &str) -> Option<&str> {
    let start = wkt.find('"')? + 1;
    let len = wkt[start..].find('"')?;
    Some(&wkt[start..start + len]).filter(|name| !name.is_empty())
}

/// The `Units` element for the CRS's linear unit: the last `UNIT`/`LENGTHUNIT` of the WKT
/// that is not angular decides between metres (the default, also for units LandXML cannot
/// name; the WKT is written too), kilometres, centimetres, millimetres and (US survey)
/// feet.
fn units_element(wkt: Option<&str>) -> String {
    let metric = |unit: &str| {
        format!(
            "<Metric areaUnit=\"squareMeter\" linearUnit=\"{unit}\" \
             volumeUnit=\"cubicMeter\" temperatureUnit=\"celsius\" pressureUnit=\"milliBars\" \
             diameterUnit=\"millimeter\" angularUnit=\"decimal degrees\" \
             directionUnit=\"decimal degrees\"/>"
        )
    };
    const FOOT: &str = "<Imperial areaUnit=\"squareFoot\" linearUnit=\"foot\" \
        volumeUnit=\"cubicYard\" temperatureUnit=\"fahrenheit\" pressureUnit=\"inHG\" \
        diameterUnit=\"inch\" angularUnit=\"decimal degrees\" \
        directionUnit=\"decimal degrees\"/>";
    const US_FOOT: &str = "<Imperial areaUnit=\"squareFoot\" linearUnit=\"USSurveyFoot\" \
        volumeUnit=\"cubicYard\" temperatureUnit=\"fahrenheit\" pressureUnit=\"inHG\" \
        diameterUnit=\"inch\" angularUnit=\"decimal degrees\" \
        directionUnit=\"decimal degrees\"/>";
    let Some(wkt) = wkt else {
        return metric("meter");
    };
    let mut factor = None;
    let upper = wkt.to_ascii_uppercase();
    let mut rest = upper.as_str();
    while let Some(at) = rest.find("UNIT[\"") {
        rest = &rest[at + 6..];
        let Some(name_end) = rest.find('"') else {
            break;
        };
        let name = &rest[..name_end];
        let value: String = rest[name_end + 1..]
            .trim_start_matches([',', ' '])
            .chars()
            .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'E' | '-' | '+'))
            .collect();
        let angular = ["DEGREE", "RADIAN", "GRAD", "ARC"]
            .iter()
            .any(|a| name.contains(a));
        if !angular {
            factor = value.parse::<f64>().ok();
        }
    }
    match factor {
        Some(f) if (f - 0.3048).abs() < 1e-9 => FOOT.to_string(),
        Some(f) if (f - 1200.0 / 3937.0).abs() < 1e-9 => US_FOOT.to_string(),
        Some(1000.0) => metric("kilometer"),
        Some(0.01) => metric("centimeter"),
        Some(0.001) => metric("millimeter"),
        _ => metric("meter"),
    }
}

/// Writes `mesh` as LandXML 1.2. The caller has checked the mesh.
pub(crate) fn write<W: Write>(mut w: W, mesh: MeshRef<'_>) -> io::Result<()> {
    let crs = mesh.crs_line();
    w.write_all(
        b"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
          <LandXML xmlns=\"http://www.landxml.org/schema/LandXML-1.2\" \
          xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" \
          xsi:schemaLocation=\"http://www.landxml.org/schema/LandXML-1.2 \
          http://www.landxml.org/schema/LandXML-1.2/LandXML-1.2.xsd\" \
          version=\"1.2\" date=\"1970-01-01\" time=\"00:00:00\" readOnly=\"false\" \
          language=\"English\">\n",
    )?;
    writeln!(
        w,
        "  <Units>\n    {}\n  </Units>",
        units_element(crs.as_deref())
    )?;
    if crs.is_some() || mesh.epsg.is_some() {
        w.write_all(b"  <CoordinateSystem")?;
        if let Some(name) = crs.as_deref().and_then(crs_name) {
            write!(w, " name=\"{}\"", escape(name))?;
        }
        if let Some(epsg) = mesh.epsg {
            write!(w, " epsgCode=\"{epsg}\"")?;
        }
        if let Some(wkt) = &crs {
            write!(w, " ogcWktCode=\"{}\"", escape(wkt))?;
        }
        w.write_all(b"/>\n")?;
    }
    writeln!(
        w,
        "  <Application name=\"tinsmith\" desc=\"error-bounded DEM to TIN\" \
         manufacturer=\"tinsmith\" version=\"{}\"/>",
        env!("CARGO_PKG_VERSION")
    )?;
    w.write_all(b"  <Surfaces>\n    <Surface name=\"tin\">\n      <Definition surfType=\"TIN\"")?;
    let heights = mesh.vertices.iter().map(|v| v[2]);
    if let (Some(min), Some(max)) = (heights.clone().reduce(f64::min), heights.reduce(f64::max)) {
        write!(w, " elevMin=\"{min:?}\" elevMax=\"{max:?}\"")?;
    }
    w.write_all(b">\n        <Pnts>\n")?;
    for (i, [x, y, z]) in mesh.vertices.iter().enumerate() {
        writeln!(
            w,
            "          <P id=\"{}\">{y:?} {x:?} {z:?}</P>",
            i as u64 + 1
        )?;
    }
    w.write_all(b"        </Pnts>\n        <Faces>\n")?;
    for &[a, b, c] in mesh.triangles {
        writeln!(
            w,
            "          <F>{} {} {}</F>",
            u64::from(a) + 1,
            u64::from(b) + 1,
            u64::from(c) + 1
        )?;
    }
    w.write_all(
        b"        </Faces>\n      </Definition>\n    </Surface>\n  </Surfaces>\n</LandXML>\n",
    )
}

/// The value of attribute `name` of `element`, unescaped.
fn attribute(element: &BytesStart<'_>, name: &str) -> Result<Option<String>, Problem> {
    for attribute in element.attributes() {
        let attribute = attribute.map_err(Problem::malformed)?;
        if attribute.key.local_name().as_ref() == name {
            let value = attribute
                .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .map_err(Problem::malformed)?;
            return Ok(Some(value.into_owned()));
        }
    }
    Ok(None)
}

/// What the text being read belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Inside {
    Nothing,
    /// A `P` with this id.
    Point(u64),
    /// A visible `F`.
    Face,
}

/// Reads the first TIN `Surface` of a LandXML file: `P` points (northing easting
/// elevation) by id, visible `F` faces (faces with `i="1"` are holes and skipped), and the
/// `CoordinateSystem`'s `epsgCode` and `ogcWktCode`.
pub(crate) fn read<R: BufRead>(r: R) -> Result<Mesh, Problem> {
    let mut reader = quick_xml::Reader::from_reader(r);
    let mut buf = Vec::new();
    let mut mesh = Mesh::default();
    let mut ids: HashMap<u64, u32> = HashMap::new();
    let mut path: Vec<String> = Vec::new();
    let mut surfaces = 0usize;
    let mut inside = Inside::Nothing;
    let mut text = String::new();
    let mut faces: Vec<[u64; 3]> = Vec::new();
    let mut saw_root = false;
    loop {
        let position = reader.buffer_position();
        let event = reader
            .read_event_into(&mut buf)
            .map_err(|e| Problem::malformed(format_args!("XML error near byte {position}: {e}")))?;
        match event {
            Event::Start(element) | Event::Empty(element) if path.len() >= MAX_DEPTH => {
                let _ = element;
                return Err(Problem::malformed("elements nested too deeply"));
            }
            Event::Start(element) => {
                let name = element.local_name().as_ref().to_owned();
                if path.is_empty() {
                    if name != "LandXML" {
                        return Err(Problem::malformed("the root element is not LandXML"));
                    }
                    saw_root = true;
                }
                if name == "Surface" && path.last().is_some_and(|p| p == "Surfaces") {
                    surfaces += 1;
                }
                let in_first_surface = surfaces == 1 && path.iter().any(|p| p == "Surface");
                if in_first_surface && name == "P" {
                    let id = attribute(&element, "id")?
                        .ok_or_else(|| Problem::malformed("a point without an id"))?;
                    let id = id.trim().parse::<u64>().map_err(|_| {
                        Problem::malformed(format_args!("point id `{id}` is not a number"))
                    })?;
                    inside = Inside::Point(id);
                    text.clear();
                } else if in_first_surface && name == "F" {
                    let hidden = attribute(&element, "i")?.is_some_and(|i| i.trim() == "1");
                    inside = if hidden {
                        Inside::Nothing
                    } else {
                        Inside::Face
                    };
                    text.clear();
                } else if name == "CoordinateSystem" {
                    read_crs(&element, &mut mesh)?;
                }
                path.push(name);
            }
            Event::Empty(element) => {
                if path.is_empty() {
                    return Err(Problem::malformed("the root element is not LandXML"));
                }
                if element.local_name().as_ref() == "CoordinateSystem" {
                    read_crs(&element, &mut mesh)?;
                }
            }
            Event::Text(t) if inside != Inside::Nothing => text.push_str(&t),
            Event::CData(t) if inside != Inside::Nothing => text.push_str(&t),
            // A character reference (`&#32;`) or one of XML's five entities in the text.
            Event::GeneralRef(r) if inside != Inside::Nothing => match r.resolve_char_ref() {
                Ok(Some(c)) => text.push(c),
                _ => match quick_xml::escape::resolve_predefined_entity(&r) {
                    Some(s) => text.push_str(s),
                    None => {
                        return Err(Problem::malformed(format_args!(
                            "unknown reference &{}; near byte {position}",
                            &*r
                        )))
                    }
                },
            },
            Event::End(_) => {
                path.pop();
                match inside {
                    Inside::Point(id) => {
                        let numbers = parse_numbers::<f64>(&text, "point", id)?;
                        let [n, e, z] = numbers;
                        let index = u32::try_from(mesh.vertices.len())
                            .map_err(|_| Problem::unsupported("more than 2^32 points"))?;
                        if ids.insert(id, index).is_some() {
                            return Err(Problem::malformed(format_args!("point id {id} repeats")));
                        }
                        mesh.vertices.push([e, n, z]);
                    }
                    Inside::Face => {
                        faces.push(parse_numbers::<u64>(&text, "face", faces.len() as u64 + 1)?);
                    }
                    Inside::Nothing => {}
                }
                inside = Inside::Nothing;
            }
            Event::Eof if !path.is_empty() => {
                return Err(Problem::malformed(format_args!(
                    "the file ends inside <{}> (truncated)",
                    path.last().map_or("", String::as_str)
                )))
            }
            Event::Eof => break,
            _ => {}
        }
        buf.clear();
    }
    if !saw_root {
        return Err(Problem::malformed(
            "the file is empty or has no LandXML element",
        ));
    }
    for (f, corners) in faces.iter().enumerate() {
        let mut triangle = [0u32; 3];
        for (index, id) in triangle.iter_mut().zip(corners) {
            *index = *ids.get(id).ok_or_else(|| {
                Problem::malformed(format_args!(
                    "face {} refers to point id {id}, which does not exist (index out of range)",
                    f + 1
                ))
            })?;
        }
        mesh.triangles.push(triangle);
    }
    Ok(mesh)
}

/// Three numbers separated by whitespace.
fn parse_numbers<T: std::str::FromStr + Copy + Default>(
    text: &str,
    what: &str,
    number: u64,
) -> Result<[T; 3], Problem> {
    let mut out = [T::default(); 3];
    let mut tokens = text.split_ascii_whitespace();
    for value in &mut out {
        *value = tokens.next().and_then(|t| t.parse().ok()).ok_or_else(|| {
            Problem::malformed(format_args!(
                "{what} {number}: `{}` is not 3 numbers",
                text.trim()
            ))
        })?;
    }
    if tokens.next().is_some() {
        return Err(Problem::unsupported(format_args!(
            "{what} {number}: more than 3 values; only triangles with 3D points are read"
        )));
    }
    Ok(out)
}

/// Takes `epsgCode` and `ogcWktCode` from a `CoordinateSystem` element.
fn read_crs(element: &BytesStart<'_>, mesh: &mut Mesh) -> Result<(), Problem> {
    if let Some(code) = attribute(element, "epsgCode")? {
        mesh.epsg = code.trim().parse().ok();
    }
    if let Some(wkt) = attribute(element, "ogcWktCode")? {
        mesh.crs_wkt = Some(wkt).filter(|w| !w.trim().is_empty());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_to_string(mesh: MeshRef<'_>) -> String {
        let mut bytes = Vec::new();
        write(&mut bytes, mesh).expect("writing to a Vec");
        String::from_utf8(bytes).expect("LandXML is text")
    }

    const VERTICES: [[f64; 3]; 4] = [
        [1_200_000.5, 500_000.25, 812.125],
        [1_200_050.0, 500_000.0, 0.1 + 0.2],
        [1_200_050.0, 500_050.0, -3.0],
        [1_200_000.0, 500_050.0, 1e-300],
    ];
    const TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
    const WKT: &str = "PROJCS[\"NAD83 / BC Albers\",GEOGCS[\"NAD83\",UNIT[\"degree\",0.0174532925199433]],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"3005\"]]";

    #[test]
    fn points_are_northing_easting_and_round_trip_exactly() -> Result<(), Problem> {
        let text = write_to_string(
            MeshRef::new(&VERTICES, &TRIANGLES)
                .with_crs_wkt(WKT)
                .with_epsg(3005),
        );
        assert!(
            text.contains("<P id=\"1\">500000.25 1200000.5 812.125</P>"),
            "{text}"
        );
        assert!(text.contains("<F>1 3 4</F>"));
        assert!(text.contains("name=\"NAD83 / BC Albers\" epsgCode=\"3005\""));
        assert!(text.contains("linearUnit=\"meter\""));
        let mesh = read(text.as_bytes())?;
        assert_eq!(mesh.vertices, VERTICES);
        assert_eq!(mesh.triangles, TRIANGLES);
        assert_eq!(mesh.epsg, Some(3005));
        assert_eq!(mesh.crs_wkt.as_deref(), Some(WKT));
        Ok(())
    }

    #[test]
    fn units_follow_the_wkt() {
        assert!(units_element(None).contains("meter"));
        assert!(units_element(Some(WKT)).contains("meter"));
        let feet = "PROJCS[\"x\",GEOGCS[\"y\",UNIT[\"degree\",0.01745]],UNIT[\"US survey foot\",0.304800609601219]]";
        assert!(units_element(Some(feet)).contains("USSurveyFoot"));
        let feet = "PROJCS[\"x\",LENGTHUNIT[\"foot\",0.3048]]";
        assert!(units_element(Some(feet)).contains("linearUnit=\"foot\""));
        let km = "PROJCS[\"x\",GEOGCS[\"y\",UNIT[\"degree\",0.01745]],UNIT[\"kilometre\",1000]]";
        assert!(units_element(Some(km)).contains("linearUnit=\"kilometer\""));
    }

    #[test]
    fn hidden_faces_other_surfaces_and_sparse_ids() -> Result<(), Problem> {
        let text = "<?xml version=\"1.0\"?><LandXML><Surfaces><Surface name=\"a\"><Definition surfType=\"TIN\">\
            <Pnts><P id=\"10\">0 0 1</P><P id=\"20\">0 1 2</P><P id=\"30\">1 1 3</P></Pnts>\
            <Faces><F>10 20 30</F><F i=\"1\">30 20 10</F></Faces></Definition></Surface>\
            <Surface name=\"b\"><Definition><Pnts><P id=\"1\">5 5 5</P></Pnts></Definition></Surface>\
            </Surfaces></LandXML>";
        let mesh = read(text.as_bytes())?;
        assert_eq!(
            mesh.vertices,
            vec![[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [1.0, 1.0, 3.0]]
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        Ok(())
    }

    #[test]
    fn cdata_and_references_in_text_are_read_as_xml_means_them() -> Result<(), Problem> {
        let text = "<LandXML><Surfaces><Surface><Definition surfType=\"TIN\"><Pnts>\
            <P id=\"1\"><![CDATA[0 0 1]]></P><P id=\"2\">0&#32;1&#x20;2</P>\
            <P id=\"3\">1 1 &#51;</P></Pnts><Faces><F>1 2 3</F></Faces></Definition>\
            </Surface></Surfaces></LandXML>";
        let mesh = read(text.as_bytes())?;
        assert_eq!(
            mesh.vertices,
            vec![[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [1.0, 1.0, 3.0]]
        );
        let unknown = text.replace("&#51;", "&three;");
        match read(unknown.as_bytes()) {
            Err(Problem::Malformed(reason)) => assert!(reason.contains("&three;"), "{reason}"),
            other => panic!("{other:?}"),
        }
        Ok(())
    }

    #[test]
    fn bad_files_are_reported() {
        let cases: [(&str, &str); 9] = [
            ("", "empty"),
            ("<LandXML><Surfaces><Surface><Pnts><P id=\"1\">1 2 3</P>", "ends inside <Pnts>"),
            ("<LandXML><Surfaces><Surface><Faces><F>1 2", "ends inside <F>"),
            ("<Other/>", "not LandXML"),
            ("<LandXML><Surfaces><Surface><Pnts><P>1 2 3</P></Pnts></Surface></Surfaces></LandXML>", "without an id"),
            ("<LandXML><Surfaces><Surface><Pnts><P id=\"1\">1 2</P></Pnts></Surface></Surfaces></LandXML>", "not 3 numbers"),
            ("<LandXML><Surfaces><Surface><Faces><F>1 2 3</F></Faces></Surface></Surfaces></LandXML>", "does not exist"),
            ("<LandXML><Surfaces><Surface><Pnts><P id=\"1\">1 2 3</P><P id=\"1\">1 2 3</P></Pnts></Surface></Surfaces></LandXML>", "repeats"),
            ("<LandXML><Surfaces></Surface></LandXML>", "XML error"),
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
