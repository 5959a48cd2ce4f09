//! Breaklines with point input: `mesh --breaklines` keeps every segment as a chain of
//! mesh edges and every point within the bound, `verify --breaklines` checks both
//! independently; 2D lines take the points' heights, 3D lines keep theirs; bad breakline
//! files are refused naming the file, with nothing written.

use crate::util::{stderr, stdout, Dir};

/// Points on a 200 m square with millimetre positions: a plane with a 4 m step up at
/// y = 100 (a cliff the Delaunay triangulation cuts across).
fn step_points(n: usize) -> String {
    let mut s = String::from("x,y,z\n");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    // The corners, so that the lines below are inside the points' hull.
    let mut points = vec![[0.0, 0.0], [200.0, 0.0], [0.0, 200.0], [200.0, 200.0]];
    while points.len() < n {
        points.push([
            (next() * 200_000.0).round() / 1000.0,
            (next() * 200_000.0).round() / 1000.0,
        ]);
    }
    for [x, y] in points {
        let z = 50.0 + 0.02 * x + if y >= 100.0 { 4.0 } else { 0.0 };
        s.push_str(&format!(
            "{:.3},{:.3},{z:.3}\n",
            500_000.0 + x,
            4_000_000.0 + y
        ));
    }
    s
}

/// A GeoJSON FeatureCollection of `geometries` (GeoJSON geometry objects).
fn feature_collection(geometries: &[&str]) -> String {
    let features: Vec<String> = geometries
        .iter()
        .map(|g| format!(r#"{{"type":"Feature","properties":{{}},"geometry":{g}}}"#))
        .collect();
    format!(
        r#"{{"type":"FeatureCollection","features":[{}]}}"#,
        features.join(",")
    )
}

/// Two crossing lines: one along the step's foot, one across it.
const CROSSING: [&str; 2] = [
    r#"{"type":"LineString","coordinates":[[500005,4000099.5],[500100,4000099.5],[500195,4000099.5]]}"#,
    r#"{"type":"LineString","coordinates":[[500150.0003,4000010],[500150,4000190]]}"#,
];

fn report(dir: &Dir, name: &str) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.path(name)).unwrap()).unwrap()
}

fn mesh(dir: &Dir, out: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["mesh", "pts.csv", "-o", out, "--max-error", "0.05"];
    args.extend_from_slice(extra);
    dir.run(&args)
}

#[test]
fn breaklines_are_chains_of_edges_and_every_point_within_the_bound() {
    let dir = Dir::new();
    dir.write("pts.csv", &step_points(4000));
    dir.write("lines.geojson", &feature_collection(&CROSSING));
    let o = mesh(
        &dir,
        "tin.ply",
        &["--breaklines", "lines.geojson", "--report", "r.json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let r = report(&dir, "r.json");
    let b = &r["breaklines"];
    assert_eq!(b["lines"], 2);
    assert_eq!(b["heights"], "interpolated from the points");
    assert_eq!(b["crossings"], 1);
    assert_eq!(b["segments_verified"], 3);
    assert_eq!(r["points_read"], 4000);
    assert!(r["measured_max_error"].as_f64().unwrap() <= 0.05);
    // Independently: every point and every segment.
    let o = dir.run(&[
        "verify",
        "pts.csv",
        "tin.ply",
        "--max-error",
        "0.05",
        "--breaklines",
        "lines.geojson",
    ]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("4000 points") && stdout(&o).contains("3 breakline segments present"),
        "{}",
        stdout(&o)
    );
    // The mesh made without them does not have them: the check can fail.
    let o = mesh(&dir, "plain.ply", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = dir.run(&[
        "verify",
        "pts.csv",
        "plain.ply",
        "--max-error",
        "0.05",
        "--breaklines",
        "lines.geojson",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("breakline segments"), "{}", stdout(&o));
    // Same input, same bytes.
    let o = mesh(&dir, "again.ply", &["--breaklines", "lines.geojson"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(dir.path("tin.ply")).unwrap(),
        std::fs::read(dir.path("again.ply")).unwrap()
    );
}

#[test]
fn three_d_lines_keep_their_heights_from_a_geopackage() {
    let dir = Dir::new();
    dir.write("pts.csv", &step_points(2000));
    // A ditch 3 m deep along x = 60, written as a GeoPackage by ogr2ogr.
    dir.write(
        "ditch.geojson",
        &feature_collection(&[
            r#"{"type":"LineString","coordinates":[[500060,4000020,47],[500060,4000080,47.5],[500060,4000180,52]]}"#,
        ]),
    );
    let o = std::process::Command::new("ogr2ogr")
        .args(["-f", "GPKG", "ditch.gpkg", "ditch.geojson"])
        .current_dir(dir.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = mesh(
        &dir,
        "tin.obj",
        &["--breaklines", "ditch.gpkg", "--report", "r.json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        report(&dir, "r.json")["breaklines"]["heights"],
        "the file's"
    );
    let obj = std::fs::read_to_string(dir.path("tin.obj")).unwrap();
    let vertices: Vec<[f64; 3]> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split(' ').map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    for want in [
        [500060.0, 4000020.0, 47.0],
        [500060.0, 4000080.0, 47.5],
        [500060.0, 4000180.0, 52.0],
    ] {
        assert!(
            vertices
                .iter()
                .any(|v| (0..3).all(|k| (v[k] - want[k]).abs() < 1e-6)),
            "no vertex {want:?}"
        );
    }
    let o = dir.run(&[
        "verify",
        "pts.csv",
        "tin.obj",
        "--max-error",
        "0.05",
        "--breaklines",
        "ditch.gpkg",
    ]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
}

#[test]
fn bad_breaklines_are_refused_naming_the_file() {
    let dir = Dir::new();
    dir.write("pts.csv", &step_points(500));
    let refused = |file: &str, problem: &str| {
        let before = dir.files();
        let o = mesh(
            &dir,
            "out.ply",
            &["--breaklines", file, "--report", "r.json"],
        );
        assert!(!o.status.success(), "{file} was accepted");
        let e = stderr(&o);
        assert!(e.contains(file) && e.contains(problem), "{file}: {e}");
        assert_eq!(dir.files(), before, "{file} left output");
    };
    dir.write(
        "points.geojson",
        &feature_collection(&[r#"{"type":"Point","coordinates":[500010,4000010]}"#]),
    );
    refused("points.geojson", "not lines or polygons");
    refused("missing.gpkg", "no such file");
    dir.write("text.geojson", "these are not lines");
    refused("text.geojson", "not a vector file");
    dir.write(
        "outside.geojson",
        &feature_collection(&[
            r#"{"type":"LineString","coordinates":[[500010,4000010],[500300,4000010]]}"#,
        ]),
    );
    refused("outside.geojson", "outside the points' extent");
    dir.write(
        "wgs84.geojson",
        &feature_collection(&[r#"{"type":"LineString","coordinates":[[3,40],[3.001,40]]}"#]),
    );
    let before = dir.files();
    let o = mesh(
        &dir,
        "out.ply",
        &["--breaklines", "wgs84.geojson", "--crs", "EPSG:32631"],
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("wgs84.geojson") && stderr(&o).contains("CRS"),
        "{}",
        stderr(&o)
    );
    assert_eq!(dir.files(), before);
}
