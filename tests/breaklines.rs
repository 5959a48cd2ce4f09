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

/// `tinsmith verify INPUT MESH --max-error BOUND --breaklines LINES`.
fn verify_lines(
    dir: &Dir,
    input: &str,
    mesh: &str,
    bound: &str,
    lines: &str,
) -> std::process::Output {
    dir.run(&[
        "verify",
        input,
        mesh,
        "--max-error",
        bound,
        "--breaklines",
        lines,
    ])
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
    let o = verify_lines(&dir, "pts.csv", "tin.ply", "0.05", "lines.geojson");
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("4000 points") && stdout(&o).contains("3 breakline segments present"),
        "{}",
        stdout(&o)
    );
    // The mesh made without them does not have them: the check can fail.
    let o = mesh(&dir, "plain.ply", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = verify_lines(&dir, "pts.csv", "plain.ply", "0.05", "lines.geojson");
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
    let o = verify_lines(&dir, "pts.csv", "tin.obj", "0.05", "ditch.gpkg");
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
    // A TIN keeps its own edges: breaklines are for points.
    let o = mesh(&dir, "tin.ply", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    dir.write("inside.geojson", &feature_collection(&[CROSSING[1]]));
    let before = dir.files();
    let o = dir.run(&[
        "mesh",
        "tin.ply",
        "-o",
        "smaller.ply",
        "--max-error",
        "0.1",
        "--breaklines",
        "inside.geojson",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("tin.ply") && stderr(&o).contains("not to a TIN"),
        "{}",
        stderr(&o)
    );
    assert_eq!(dir.files(), before);
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

/// A square polygon ring `[x0, y0]`-`[x1, y1]` (metres on the fixture's square).
fn ring(x0: f64, y0: f64, x1: f64, y1: f64) -> String {
    let p = |x: f64, y: f64| format!("[{},{}]", 500_000.0 + x, 4_000_000.0 + y);
    format!(
        "[{},{},{},{},{}]",
        p(x0, y0),
        p(x1, y0),
        p(x1, y1),
        p(x0, y1),
        p(x0, y0)
    )
}

#[test]
fn a_boundary_clips_the_tin_and_its_holes_and_verify_measures_the_points_inside() {
    let dir = Dir::new();
    dir.write("pts.csv", &step_points(3000));
    let polygon = format!(
        r#"{{"type":"Polygon","coordinates":[{},{}]}}"#,
        ring(20.0, 20.0, 180.0, 180.0),
        ring(80.0, 120.0, 120.0, 160.0)
    );
    dir.write("outline.geojson", &feature_collection(&[&polygon]));
    // A breakline inside the outline, touching neither ring.
    dir.write(
        "inside.geojson",
        &feature_collection(&[
            r#"{"type":"LineString","coordinates":[[500030,4000099.5],[500170,4000099.5]]}"#,
        ]),
    );
    let o = mesh(
        &dir,
        "tin.ply",
        &[
            "--boundary",
            "outline.geojson",
            "--breaklines",
            "inside.geojson",
            "--report",
            "r.json",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("points outside the boundary dropped"));
    let r = report(&dir, "r.json");
    let outside = r["points_outside"].as_u64().unwrap();
    // About 1 - (160^2 - 40^2) / 200^2 = 40 % of the points are outside.
    assert!((1000..1400).contains(&outside), "{outside}");
    assert_eq!(r["points_read"], 3000);
    let verify = |mesh: &str, extra: &[&str]| {
        let mut args = vec!["verify", "pts.csv", mesh, "--max-error", "0.05"];
        args.extend_from_slice(extra);
        dir.run(&args)
    };
    let o = verify(
        "tin.ply",
        &[
            "--boundary",
            "outline.geojson",
            "--breaklines",
            "inside.geojson",
        ],
    );
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let inside = 3000 - outside;
    assert!(
        stdout(&o).contains(&format!("{inside} points")),
        "{}",
        stdout(&o)
    );
    // Without --boundary the dropped points are outside the mesh: the check can fail.
    let o = verify("tin.ply", &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stdout(&o).contains(&format!("{outside} points outside the mesh")),
        "{}",
        stdout(&o)
    );
}

#[test]
fn a_longest_hull_edge_drops_the_points_beyond_a_concave_outline() {
    let dir = Dir::new();
    // An L: the points of the square's upper right quarter removed.
    let all = step_points(3000);
    let mut text = String::from("x,y,z\n");
    let mut kept = 0;
    for line in all.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|t| t.parse().unwrap()).collect();
        if v[0] - 500_000.0 <= 100.0 || v[1] - 4_000_000.0 <= 100.0 {
            text.push_str(line);
            text.push('\n');
            kept += 1;
        }
    }
    dir.write("pts.csv", &text);
    let o = mesh(&dir, "convex.ply", &["--report", "convex.json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = mesh(
        &dir,
        "concave.ply",
        &["--hull-edge-length", "25", "--report", "concave.json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (convex, concave) = (report(&dir, "convex.json"), report(&dir, "concave.json"));
    assert_eq!(concave["hull_edge_length"], 25.0);
    // The notch's long triangles go; the L's points stay (25 m is far above their
    // spacing).
    assert!(concave["delaunay_triangles"].as_u64() < convex["delaunay_triangles"].as_u64());
    assert_eq!(concave["points_outside"], 0);
    let o = dir.run(&["verify", "pts.csv", "concave.ply", "--max-error", "0.05"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains(&format!("{kept} points")),
        "{}",
        stdout(&o)
    );
    // Too short for the points' spacing: triangles and points go, counted.
    let o = mesh(
        &dir,
        "eaten.ply",
        &["--hull-edge-length", "2", "--report", "eaten.json"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        report(&dir, "eaten.json")["points_outside"]
            .as_u64()
            .unwrap()
            > 0
    );
}

#[test]
fn bad_boundaries_are_refused_naming_the_file() {
    let dir = Dir::new();
    dir.write("pts.csv", &step_points(500));
    let refused = |args: &[&str], file: &str, problem: &str| {
        let before = dir.files();
        let mut all = args.to_vec();
        all.extend(["--report", "r.json"]);
        let o = mesh(&dir, "out.ply", &all);
        assert!(!o.status.success(), "{args:?} was accepted");
        let e = stderr(&o);
        assert!(e.contains(file) && e.contains(problem), "{args:?}: {e}");
        assert_eq!(dir.files(), before, "{args:?} left output");
    };
    dir.write("lines.geojson", &feature_collection(&CROSSING));
    refused(
        &["--boundary", "lines.geojson"],
        "lines.geojson",
        "not polygons",
    );
    refused(&["--boundary", "none.gpkg"], "none.gpkg", "no such file");
    // Between points: a ring far smaller than their spacing holds none.
    let tiny = format!(
        r#"{{"type":"Polygon","coordinates":[{}]}}"#,
        ring(50.0001, 50.0001, 50.0004, 50.0004)
    );
    dir.write("tiny.geojson", &feature_collection(&[&tiny]));
    refused(
        &["--boundary", "tiny.geojson"],
        "tiny.geojson",
        "none of the points is inside",
    );
    let outline = format!(
        r#"{{"type":"Polygon","coordinates":[{}]}}"#,
        ring(20.0, 20.0, 180.0, 180.0)
    );
    dir.write("outline.geojson", &feature_collection(&[&outline]));
    // The crossing lines leave the outline.
    refused(
        &[
            "--boundary",
            "outline.geojson",
            "--breaklines",
            "lines.geojson",
        ],
        "outline.geojson",
        "crosses boundary ring 1",
    );
    let wide = format!(
        r#"{{"type":"Polygon","coordinates":[{}]}}"#,
        ring(-20.0, 20.0, 180.0, 180.0)
    );
    dir.write("wide.geojson", &feature_collection(&[&wide]));
    refused(
        &["--boundary", "wide.geojson"],
        "wide.geojson",
        "outside the points' extent",
    );
}

#[test]
fn a_raster_with_breaklines_keeps_them_and_the_bound_at_every_sample() {
    let dir = Dir::new();
    // 40 x 30 samples, 2 m apart, a ridge along a diagonal; lower-left corner at (1000,
    // 2000), so sample centres are at odd metres.
    let mut asc = String::from(
        "ncols 40\nnrows 30\nxllcorner 1000\nyllcorner 2000\ncellsize 2\nNODATA_value -9999\n",
    );
    for row in 0..30 {
        let line: Vec<String> = (0..40)
            .map(|col| {
                let (x, y) = (f64::from(col), f64::from(29 - row));
                format!(
                    "{:.2}",
                    10.0 + 3.0 * (-(x - y - 5.0).powi(2) / 20.0).exp() + 0.1 * x
                )
            })
            .collect();
        asc.push_str(&line.join(" "));
        asc.push('\n');
    }
    dir.write("dem.asc", &asc);
    // Two crossing lines whose crossing falls between samples.
    dir.write(
        "lines.geojson",
        &feature_collection(&[
            r#"{"type":"LineString","coordinates":[[1004,2010.2],[1070,2040.6]]}"#,
            r#"{"type":"LineString","coordinates":[[1040.3,2004],[1036.1,2055]]}"#,
        ]),
    );
    let o = dir.run(&[
        "mesh",
        "dem.asc",
        "-o",
        "tin.ply",
        "--max-error",
        "0.05",
        "--breaklines",
        "lines.geojson",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = report(&dir, "r.json");
    assert_eq!(r["points_read"], 1200);
    assert_eq!(r["breaklines"]["crossings"], 1);
    assert_eq!(r["breaklines"]["segments_verified"], 2);
    let verify = |extra: &[&str]| {
        let mut args = vec!["verify", "dem.asc", "tin.ply", "--max-error", "0.05"];
        args.extend_from_slice(extra);
        dir.run(&args)
    };
    let o = verify(&["--breaklines", "lines.geojson"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("1200 points"), "{}", stdout(&o));
    // At a tenth of the bound the same mesh fails: every sample is measured.
    let o = verify_lines(&dir, "dem.asc", "tin.ply", "0.005", "lines.geojson");
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
}

#[test]
fn lines_that_continue_one_another_and_rings_keep_their_vertices_and_lose_points_on_them() {
    let dir = Dir::new();
    // The step's points, and points lying exactly on the lines below (every metre).
    let mut points = step_points(3000);
    for k in 10..=190 {
        points.push_str(&format!(
            "{},4000050.000,{:.3}\n",
            500_000 + k,
            50.0 + 0.02 * k as f64
        ));
    }
    for k in 41..80 {
        let z = 54.0 + 0.02 * k as f64;
        points.push_str(&format!("{},4000140.000,{z:.3}\n", 500_000 + k));
        points.push_str(&format!("{},4000170.000,{z:.3}\n", 500_000 + k));
    }
    dir.write("pts.csv", &points);
    // Two lines, the second going straight on from the first's end; a closed ring whose
    // first vertex is in the middle of a straight side.
    dir.write(
        "lines.geojson",
        &feature_collection(&[
            r#"{"type":"LineString","coordinates":[[500010,4000050],[500100,4000050]]}"#,
            r#"{"type":"LineString","coordinates":[[500100,4000050],[500190,4000050]]}"#,
            r#"{"type":"LineString","coordinates":[[500060,4000140],[500080,4000140],[500080,4000170],[500040,4000170],[500040,4000140],[500060,4000140]]}"#,
        ]),
    );
    let o = mesh(&dir, "tin.obj", &["--breaklines", "lines.geojson"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = verify_lines(&dir, "pts.csv", "tin.obj", "0.05", "lines.geojson");
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    // On the plane, the points lying on the lines go; the lines' own vertices stay.
    let obj = std::fs::read_to_string(dir.path("tin.obj")).unwrap();
    let on_row: Vec<f64> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            l.split_whitespace()
                .map(|c| c.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .filter(|v| (v[1] - 4_000_050.0).abs() < 1e-3)
        .map(|v| v[0])
        .collect();
    for x in [500_010.0, 500_100.0, 500_190.0] {
        assert!(
            on_row.iter().any(|&v| (v - x).abs() < 1e-3),
            "{x} missing: {on_row:?}"
        );
    }
    assert!(
        on_row.len() < 20,
        "{} of 181 points on the line kept",
        on_row.len()
    );
}
