//! `verify` and `contour --mesh` on meshes as other tools rewrite them: the same TIN with
//! vertices repeated per triangle, heights rounded to six decimals, polygons wound
//! clockwise (shapefiles), ogr2ogr's EPSG 4979 label and one-part MultiPolygons.

use std::process::Command;

use crate::util::{fixture, stderr, Dir};

const BEC: &str = "becmodel_dem_bc_albers_50m.tif";

/// `ogr2ogr ARGS...` in `d`; gdal-bin is installed by `make deps`.
fn ogr2ogr(d: &Dir, args: &[&str]) {
    let o = Command::new("ogr2ogr")
        .current_dir(d.path(""))
        .args(args)
        .output()
        .expect("ogr2ogr (Debian gdal-bin, installed by `make deps`) must be on PATH");
    assert!(o.status.success(), "ogr2ogr {args:?}: {}", stderr(&o));
}

fn passes(d: &Dir, args: &[&str]) -> String {
    let o = d.run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    stderr(&o)
}

/// `obj` rewritten as another tool might: every triangle with its own three vertices,
/// coordinates printed with six decimals.
fn unwelded_six_decimals(obj: &str) -> String {
    let mut vertices = Vec::new();
    let mut out = String::new();
    let mut next = 1;
    for line in obj.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let v: Vec<f64> = words.map(|w| w.parse().expect("a number")).collect();
                vertices.push(v);
            }
            Some("f") => {
                let mut face = String::from("f");
                for w in words {
                    let i: usize = w.split('/').next().unwrap().parse().expect("an index");
                    let v = &vertices[i - 1];
                    out.push_str(&format!("v {:.6} {:.6} {:.6}\n", v[0], v[1], v[2]));
                    face.push_str(&format!(" {next}"));
                    next += 1;
                }
                out.push_str(&face);
                out.push('\n');
            }
            _ => {}
        }
    }
    out
}

#[test]
fn contour_of_an_unwelded_rounded_copy_is_the_same_lines() {
    let d = Dir::new();
    let input = fixture(BEC);
    passes(
        &d,
        // Vertices at their samples: the rounded copy's heights snap back to them.
        &[
            "mesh",
            &input,
            "-o",
            "m.obj",
            "--max-error",
            "10",
            "--vertex-heights",
            "samples",
            "-q",
        ],
    );
    let obj = std::fs::read_to_string(d.path("m.obj")).unwrap();
    let copy = unwelded_six_decimals(&obj);
    assert!(copy.lines().filter(|l| l.starts_with("v ")).count() > 10_000);
    d.write("copy.obj", &copy);
    // verify welds the repeated vertices and measures the rounded heights.
    passes(&d, &["verify", &input, "copy.obj", "--max-error", "10"]);
    let levels = ["--interval", "100", "--geojson-source-crs", "-q"];
    for (mesh, out) in [("m.obj", "a.geojson"), ("copy.obj", "b.geojson")] {
        let mut args = vec!["contour", input.as_str(), "--mesh", mesh, "-o", out];
        args.extend(levels);
        passes(&d, &args);
    }
    let (a, b) = (
        std::fs::read(d.path("a.geojson")).unwrap(),
        std::fs::read(d.path("b.geojson")).unwrap(),
    );
    assert!(a.len() > 10_000);
    assert!(a == b, "the rewritten mesh gave other lines");
}

#[test]
fn gis_rewrites_of_a_geojson_mesh_verify_and_contour() {
    let d = Dir::new();
    let input = fixture(BEC);
    passes(
        &d,
        &[
            "mesh",
            &input,
            "-o",
            "wgs.geojson",
            "--max-error",
            "10",
            "-q",
        ],
    );
    passes(
        &d,
        &[
            "mesh",
            &input,
            "-o",
            "src.geojson",
            "--max-error",
            "10",
            "--geojson-source-crs",
            "-q",
        ],
    );
    // ogr2ogr labels WGS84 with heights EPSG 4979; a shapefile winds rings clockwise; -nlt
    // MULTIPOLYGON makes each triangle a one-part MultiPolygon.
    ogr2ogr(&d, &["-f", "GeoJSON", "ogr.geojson", "wgs.geojson"]);
    let ogr = std::fs::read_to_string(d.path("ogr.geojson")).unwrap();
    assert!(ogr.contains("4979"), "the case this test is about");
    ogr2ogr(&d, &["-f", "FlatGeobuf", "ogr.fgb", "wgs.geojson"]);
    ogr2ogr(&d, &["-f", "ESRI Shapefile", "shp", "src.geojson"]);
    ogr2ogr(&d, &["-f", "GeoJSON", "cw.geojson", "shp/src.shp"]);
    ogr2ogr(&d, &["-f", "FlatGeobuf", "cw.fgb", "shp/src.shp"]);
    ogr2ogr(
        &d,
        &[
            "-f",
            "GeoJSON",
            "multi.geojson",
            "src.geojson",
            "-nlt",
            "MULTIPOLYGON",
        ],
    );
    ogr2ogr(
        &d,
        &[
            "-f",
            "FlatGeobuf",
            "multi.fgb",
            "src.geojson",
            "-nlt",
            "MULTIPOLYGONZ",
        ],
    );
    for mesh in [
        "ogr.geojson",
        "ogr.fgb",
        "cw.geojson",
        "cw.fgb",
        "multi.geojson",
        "multi.fgb",
    ] {
        passes(&d, &["verify", &input, mesh, "--max-error", "10"]);
        passes(
            &d,
            &[
                "contour",
                &input,
                "--mesh",
                mesh,
                "-o",
                &format!("{mesh}.lines.fgb"),
                "--interval",
                "100",
                "-q",
            ],
        );
    }
    // An OBJ wound the other way round is not the same mesh (its faces point down), and
    // the message says so.
    passes(
        &d,
        &["mesh", &input, "-o", "m.obj", "--max-error", "10", "-q"],
    );
    let obj = std::fs::read_to_string(d.path("m.obj")).unwrap();
    let reversed: String = obj
        .lines()
        .map(|l| match l.strip_prefix("f ") {
            Some(rest) => {
                let w: Vec<&str> = rest.split_whitespace().collect();
                format!("f {} {} {}\n", w[0], w[2], w[1])
            }
            None => format!("{l}\n"),
        })
        .collect();
    d.write("down.obj", &reversed);
    let o = d.run(&["verify", &input, "down.obj"]);
    assert!(!o.status.success());
    assert!(
        crate::util::stdout(&o).contains("every triangle is wound the other way round")
            || stderr(&o).contains("every triangle is wound the other way round"),
        "{}{}",
        crate::util::stdout(&o),
        stderr(&o)
    );
}

#[test]
fn contour_takes_heights_rounded_to_six_decimals_as_the_samples() {
    // Float heights with more digits than a six-decimal OBJ keeps.
    let d = Dir::new();
    let mut asc = String::from("ncols 40\nnrows 30\nxllcorner 0\nyllcorner 0\ncellsize 1\n");
    for y in 0..30 {
        let row: Vec<String> = (0..40)
            .map(|x| {
                let (x, y) = (f64::from(x), f64::from(y));
                format!(
                    "{}",
                    100.0 + (x / 7.0).sin() * 13.0 + (y / 5.0).cos() * 7.0 + x / 3.0
                )
            })
            .collect();
        asc.push_str(&row.join(" "));
        asc.push('\n');
    }
    d.write("f.asc", &asc);
    passes(
        &d,
        &[
            "mesh",
            "f.asc",
            "-o",
            "m.obj",
            "--max-error",
            "0.5",
            "--vertex-heights",
            "samples",
            "-q",
        ],
    );
    let obj = std::fs::read_to_string(d.path("m.obj")).unwrap();
    let copy = unwelded_six_decimals(&obj);
    assert_ne!(copy, obj);
    d.write("copy.obj", &copy);
    for (mesh, out) in [("m.obj", "a.geojson"), ("copy.obj", "b.geojson")] {
        passes(
            &d,
            &[
                "contour",
                "f.asc",
                "--mesh",
                mesh,
                "-o",
                out,
                "--interval",
                "2",
                "-q",
            ],
        );
    }
    assert!(
        std::fs::read(d.path("a.geojson")).unwrap() == std::fs::read(d.path("b.geojson")).unwrap()
    );
}

#[test]
fn a_global_mesh_wound_clockwise_verifies_across_the_seam() {
    // A 1° WGS84 grid whose first and last columns are the same meridian (-180 and 180):
    // placing triangles around the seam relied on their counter-clockwise winding, so a
    // shapefile round trip (clockwise rings, WGS84 as WKT alone) failed to verify.
    let d = Dir::new();
    let mut asc =
        String::from("ncols 361\nnrows 181\nxllcorner -180.5\nyllcorner -90.5\ncellsize 1\n");
    for row in 0..181 {
        let lat = f64::from(90 - row);
        let line: Vec<String> = (0..361)
            .map(|col| {
                let lon = f64::from(col - 180);
                let z = 1000.0 * lon.to_radians().sin() * lat.to_radians().cos()
                    + 200.0 * (3.0 * lat).to_radians().cos();
                format!("{z:.3}")
            })
            .collect();
        asc.push_str(&line.join(" "));
        asc.push('\n');
    }
    d.write("g.asc", &asc);
    d.write(
        "g.prj",
        "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]",
    );
    passes(
        &d,
        &[
            "mesh",
            "g.asc",
            "-o",
            "g.geojson",
            "--max-error",
            "50",
            "-q",
        ],
    );
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("g.geojson")).unwrap()).unwrap();
    for feature in json["features"].as_array_mut().unwrap() {
        let geometry = &mut feature["geometry"];
        let polygons = match geometry["type"].as_str().unwrap() {
            "Polygon" => vec![&mut geometry["coordinates"]],
            _ => geometry["coordinates"]
                .as_array_mut()
                .unwrap()
                .iter_mut()
                .collect(),
        };
        for polygon in polygons {
            for ring in polygon.as_array_mut().unwrap() {
                ring.as_array_mut().unwrap().reverse();
            }
        }
    }
    d.write("cw.geojson", &json.to_string());
    ogr2ogr(&d, &["-f", "ESRI Shapefile", "shp", "g.geojson"]);
    ogr2ogr(&d, &["-f", "FlatGeobuf", "shp.fgb", "shp/g.shp"]);
    for mesh in ["g.geojson", "cw.geojson", "shp.fgb"] {
        passes(&d, &["verify", "g.asc", mesh, "--max-error", "50"]);
    }
}

#[test]
fn a_mesh_on_another_geographic_datum_is_not_taken_for_wgs84() {
    // A raster whose CRS is ED50 given as WKT alone (no EPSG code): its FlatGeobuf and
    // source-CRS GeoJSON meshes carry that WKT and must read back as they are. Taking it
    // for WGS84 (PROJ passes far-away test points through ED50 unchanged) moved every
    // vertex by the datum shift.
    let d = Dir::new();
    let mut asc =
        String::from("ncols 40\nnrows 30\nxllcorner 6.0\nyllcorner 49.5\ncellsize 0.01\n");
    for row in 0..30 {
        let line: Vec<String> = (0..40)
            .map(|col| {
                format!(
                    "{:.2}",
                    300.0
                        + 50.0 * (f64::from(col) / 6.0).sin()
                        + 30.0 * (f64::from(row) / 4.0).cos()
                )
            })
            .collect();
        asc.push_str(&line.join(" "));
        asc.push('\n');
    }
    d.write("ed.asc", &asc);
    d.write(
        "ed.prj",
        "GEOGCS[\"my ED50\",DATUM[\"European_Datum_1950\",SPHEROID[\"International 1924\",6378388,297]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]",
    );
    passes(
        &d,
        &["mesh", "ed.asc", "-o", "ed.fgb", "--max-error", "2", "-q"],
    );
    passes(
        &d,
        &[
            "mesh",
            "ed.asc",
            "-o",
            "ed.geojson",
            "--max-error",
            "2",
            "--geojson-source-crs",
            "-q",
        ],
    );
    for mesh in ["ed.fgb", "ed.geojson"] {
        passes(&d, &["verify", "ed.asc", mesh, "--max-error", "2"]);
    }
}
