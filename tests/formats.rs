//! Every output format, checked by independent readers — GDAL's `ogrinfo` and
//! `gdaltransform`, trimesh (PyPI), the Khronos glTF validator (npm), Python's
//! `xml.etree` — and by `tinsmith verify` reading each file back.
//!
//! The oracles are installed by `make deps` (`.venv/`, `.tools/`). The tests that need
//! them are `#[ignore]`d, so that `cargo test` passes with only GDAL installed; `make test`
//! runs them (`--include-ignored`). A missing oracle fails the test with the command that
//! installs it.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::util::{
    assert_fails_naming, fixture, gdaltransform, run_under_ulimit, stderr, stdout, venv_python, Dir,
};

/// The small DEM most tests use: 100 x 80 Float32, EPSG:3857, nodata.
const DEM: &str = "tintn_valid_raster_3857.tif";
const E: &str = "0.5";

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Fails the test when the glTF validator is missing.
fn require_gltf_validator() {
    let modules = std::env::var_os("TINSMITH_NODE_MODULES")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join(".tools/node_modules"));
    let present = modules.join("gltf-validator").exists();
    require_oracle(present, "gltf-validator in .tools/node_modules");
}

/// Fails when an oracle is missing, with the command that installs it.
fn require_oracle(present: bool, what: &str) {
    assert!(present, "oracle missing: {what}; run `make deps`");
}

/// Runs a program, asserting success; returns stdout.
fn run(program: &str, args: &[&str]) -> String {
    let out = Command::new(program)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {program}: {e}"));
    assert!(
        out.status.success(),
        "{program} {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Meshes `dem` into `name` (extra flags appended), asserting success; returns the
/// `--report` JSON.
fn mesh(d: &Dir, dem: &str, name: &str, e: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "mesh",
        dem,
        "-o",
        name,
        "--max-error",
        e,
        "--report",
        "r.json",
        "-q",
    ];
    args.extend_from_slice(extra);
    let o = d.run(&args);
    assert!(o.status.success(), "mesh {name} failed: {}", stderr(&o));
    serde_json::from_slice(&std::fs::read(d.path("r.json")).expect("report")).expect("JSON")
}

/// `tinsmith verify` on a written file: must pass within `e`; returns the JSON report.
fn verify(d: &Dir, dem: &str, name: &str, e: &str, extra: &[&str]) -> Value {
    let mut args = vec!["verify", dem, name, "--max-error", e, "--json"];
    args.extend_from_slice(extra);
    let o = d.run(&args);
    let report: Value = serde_json::from_str(&stdout(&o))
        .unwrap_or_else(|_| panic!("verify {name}: {} {}", stdout(&o), stderr(&o)));
    assert!(o.status.success(), "verify {name} failed: {report:#}");
    assert!(report["max_error"].as_f64().expect("max_error") <= e.parse::<f64>().expect("E"));
    assert_eq!(report["uncovered_samples"], 0, "{name}");
    report
}

/// A mesh as an oracle read it: positions and triangles.
#[derive(Debug)]
struct Read {
    vertices: Vec<[f64; 3]>,
    faces: Vec<[usize; 3]>,
    json: Value,
}

/// Reads a mesh file with trimesh.
fn trimesh(python: &Path, path: &Path) -> Read {
    let script = repo().join("tests/oracles/mesh_read.py");
    let text = run(
        &python.to_string_lossy(),
        &[&script.to_string_lossy(), &path.to_string_lossy()],
    );
    let json: Value = serde_json::from_str(&text).expect("oracle JSON");
    let vertices = json["vertices"]
        .as_array()
        .expect("vertices")
        .iter()
        .map(|v| [0, 1, 2].map(|i| v[i].as_f64().expect("coordinate")))
        .collect();
    let faces = json["faces"]
        .as_array()
        .expect("faces")
        .iter()
        .map(|f| [0, 1, 2].map(|i| f[i].as_u64().expect("index") as usize))
        .collect();
    Read {
        vertices,
        faces,
        json,
    }
}

/// Each triangle as its corners, rotated to start at the smallest corner (orientation
/// kept), sorted: comparable across formats whatever their vertex and triangle order.
fn canonical(vertices: &[[f64; 3]], faces: &[[usize; 3]]) -> Vec<[[f64; 3]; 3]> {
    let mut triangles: Vec<[[f64; 3]; 3]> = faces
        .iter()
        .map(|f| {
            let c = f.map(|i| vertices[i]);
            let first = (0..3)
                .min_by(|&a, &b| c[a].partial_cmp(&c[b]).expect("finite"))
                .expect("three corners");
            [c[first], c[(first + 1) % 3], c[(first + 2) % 3]]
        })
        .collect();
    triangles.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    triangles
}

/// Asserts two canonical triangle lists are equal within `tolerance` per coordinate.
fn assert_same_triangles(a: &[[[f64; 3]; 3]], b: &[[[f64; 3]; 3]], tolerance: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: triangle counts");
    let mut worst = 0.0f64;
    for (s, t) in a.iter().zip(b) {
        for (p, q) in s.iter().zip(t) {
            for (x, y) in p.iter().zip(q) {
                worst = worst.max((x - y).abs());
            }
        }
    }
    assert!(worst <= tolerance, "{what}: coordinates differ by {worst}");
}

/// The triangles in `ogrinfo -al` output: `TRIANGLE Z ((...))` or `POLYGON Z ((...))`
/// lines, as corner triples.
fn ogr_triangles(text: &str) -> Vec<[[f64; 3]; 3]> {
    let mut triangles = Vec::new();
    for line in text.lines().map(str::trim) {
        let Some(ring) = line
            .strip_prefix("TRIANGLE Z ((")
            .or_else(|| line.strip_prefix("POLYGON Z (("))
        else {
            continue;
        };
        let ring = ring.trim_end_matches("))");
        let points: Vec<[f64; 3]> = ring
            .split(',')
            .map(|p| {
                let v: Vec<f64> = p
                    .split_ascii_whitespace()
                    .map(|c| c.parse().expect("number"))
                    .collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        assert_eq!(points.len(), 4, "{line}");
        assert_eq!(points[0], points[3], "closed ring: {line}");
        triangles.push([points[0], points[1], points[2]]);
    }
    triangles
}

/// `canonical` of triangles given by corners.
fn canonical_corners(triangles: &[[[f64; 3]; 3]]) -> Vec<[[f64; 3]; 3]> {
    let vertices: Vec<[f64; 3]> = triangles.iter().flatten().copied().collect();
    let faces: Vec<[usize; 3]> = (0..triangles.len())
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    canonical(&vertices, &faces)
}

/// The value after `key:` on the line of `ogrinfo -so` output that starts with it.
fn ogr_field<'a>(text: &'a str, key: &str) -> &'a str {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .map(str::trim)
        .unwrap_or_else(|| panic!("no `{key}` in ogrinfo output:\n{text}"))
}

#[test]
fn every_tin_format_reads_back_and_verifies() {
    let d = Dir::new();
    let dem = fixture(DEM);
    for ext in ["ply", "obj", "stl", "glb", "geojson", "fgb", "xml"] {
        let name = format!("m.{ext}");
        let report = mesh(&d, &dem, &name, E, &[]);
        let verified = verify(&d, &dem, &name, E, &[]);
        assert_eq!(verified["triangles"], report["triangles_after"], "{ext}");
        assert_eq!(verified["vertices"], report["vertices_after"], "{ext}");
        assert_eq!(
            report["format"],
            if ext == "xml" {
                "landxml"
            } else if ext == "fgb" {
                "fgb"
            } else {
                ext
            }
        );
    }
    // The CRS goes into a .prj sidecar for the formats that cannot hold it.
    let srs = run(
        "gdalsrsinfo",
        &["-o", "epsg", &d.path("m.prj").to_string_lossy()],
    );
    assert!(srs.contains("EPSG:3857"), "{srs}");
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn trimesh_reads_ply_obj_stl_and_glb_with_the_same_triangles() {
    let python = venv_python();
    let d = Dir::new();
    let dem = fixture(DEM);
    // Vertices at their samples: STL and glTF decimate to the bound less their float32
    // rounding, which on these integer heights leaves the same TIN only then.
    let samples = ["--vertex-heights", "samples"];
    let report = mesh(&d, &dem, "m.ply", E, &samples);
    let ply = trimesh(&python, &d.path("m.ply"));
    assert_eq!(
        ply.vertices.len() as u64,
        report["vertices_after"].as_u64().expect("count")
    );
    assert_eq!(
        ply.faces.len() as u64,
        report["triangles_after"].as_u64().expect("count")
    );
    let reference = canonical(&ply.vertices, &ply.faces);

    mesh(&d, &dem, "m.obj", E, &samples);
    let obj = trimesh(&python, &d.path("m.obj"));
    assert_eq!(obj.vertices, ply.vertices, "OBJ keeps every f64 exactly");
    assert_eq!(obj.faces, ply.faces);

    for ext in ["stl", "glb"] {
        let name = format!("m.{ext}");
        let report = mesh(&d, &dem, &name, E, &samples);
        let origin: Vec<f64> = report["local_origin"]
            .as_array()
            .expect("local_origin in the report")
            .iter()
            .map(|c| c.as_f64().expect("number"))
            .collect();
        let read = trimesh(&python, &d.path(&name));
        assert_eq!(read.vertices.len(), ply.vertices.len(), "{ext}");
        assert_eq!(read.faces.len(), ply.faces.len(), "{ext}");
        // STL has lost the origin (it is in our header, which trimesh ignores); glTF
        // holds it in the node translation, which trimesh applies.
        let vertices: Vec<[f64; 3]> = read
            .vertices
            .iter()
            .map(|v| match ext {
                "stl" => [0, 1, 2].map(|i| v[i] + origin[i]),
                _ => *v,
            })
            .collect();
        // float32 offsets from an origin mid-extent: well below a millimetre here.
        assert_same_triangles(&canonical(&vertices, &read.faces), &reference, 1e-3, ext);
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn stl_base_makes_a_watertight_solid_over_holes_and_components() {
    let d = Dir::new();
    // Half the grid is nodata: an irregular outline.
    let dem = fixture("landlab_hugo_site.asc");
    let report = mesh(&d, &dem, "solid.stl", E, &["--base", "-10"]);
    // The reader drops the walls and the bottom: the top verifies.
    verify(&d, &dem, "solid.stl", E, &[]);
    let python = venv_python();
    let read = trimesh(&python, &d.path("solid.stl"));
    assert_eq!(
        read.json["watertight"], true,
        "every edge used exactly twice"
    );
    assert_eq!(read.json["winding_consistent"], true);
    assert!(read.json["volume"].as_f64().expect("volume") > 0.0);
    let top = report["triangles_after"].as_u64().expect("count") as usize;
    assert!(read.faces.len() > 2 * top, "walls and a bottom were added");
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn gltf_validator_finds_no_errors() {
    require_gltf_validator();
    let d = Dir::new();
    let small = fixture(DEM);
    // The sample DEM keeps > 65535 vertices: 32-bit indices.
    let large = fixture("becmodel_dem_bc_albers_50m.tif");
    let script = repo().join("tests/oracles/gltf_validate.js");
    for (dem, name, eps, extra) in [
        (&small, "u16.glb", "5", &[][..]),
        (&small, "normals.glb", "5", &["--normals"][..]),
        (&large, "u32.glb", "1", &["--normals"][..]),
    ] {
        mesh(&d, dem, name, eps, extra);
        let text = run(
            "node",
            &[&script.to_string_lossy(), &d.path(name).to_string_lossy()],
        );
        let report: Value = serde_json::from_str(&text).expect("validator JSON");
        assert_eq!(report["issues"]["numErrors"], 0, "{name}: {report:#}");
        assert_eq!(report["issues"]["numWarnings"], 0, "{name}: {report:#}");
        if name == "u32.glb" {
            let vertices = report["info"]["totalVertexCount"].as_u64().expect("count");
            assert!(vertices > 65_535, "{vertices}");
        }
        verify(&d, dem, name, eps, &[]);
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn ogrinfo_reads_flatgeobuf_triangles_equal_to_the_ply() {
    let python = venv_python();
    let d = Dir::new();
    let dem = fixture(DEM);
    let report = mesh(&d, &dem, "m.ply", E, &[]);
    let ply = trimesh(&python, &d.path("m.ply"));
    mesh(&d, &dem, "m.fgb", E, &[]);
    let fgb = d.path("m.fgb").to_string_lossy().into_owned();
    let summary = run("ogrinfo", &["-so", "-al", &fgb]);
    assert_eq!(ogr_field(&summary, "Geometry:"), "3D Polygon");
    assert_eq!(
        ogr_field(&summary, "Feature Count:"),
        report["triangles_after"].to_string()
    );
    assert!(summary.contains("ID[\"EPSG\",3857]"), "{summary}");
    let all = run("ogrinfo", &["-al", "-q", &fgb]);
    assert_same_triangles(
        &canonical_corners(&ogr_triangles(&all)),
        &canonical(&ply.vertices, &ply.faces),
        1e-6,
        "FlatGeobuf",
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn ogrinfo_reads_geojson_in_wgs84_and_in_the_source_crs() {
    let python = venv_python();
    let d = Dir::new();
    let dem = fixture(DEM);
    let report = mesh(&d, &dem, "m.ply", E, &[]);
    let ply = trimesh(&python, &d.path("m.ply"));

    // Default: RFC 7946, WGS84 longitude/latitude, compared with GDAL's own transform of
    // the PLY's vertices.
    mesh(&d, &dem, "wgs84.geojson", E, &[]);
    let path = d.path("wgs84.geojson").to_string_lossy().into_owned();
    let summary = run("ogrinfo", &["-so", "-al", &path]);
    assert_eq!(ogr_field(&summary, "Geometry:"), "3D Polygon");
    assert_eq!(
        ogr_field(&summary, "Feature Count:"),
        report["triangles_after"].to_string()
    );
    assert!(summary.contains("GEOGCRS[\"WGS 84\""), "{summary}");
    let lonlat = gdaltransform("EPSG:3857", "EPSG:4326", &ply.vertices);
    let all = run("ogrinfo", &["-al", "-q", &path]);
    assert_same_triangles(
        &canonical_corners(&ogr_triangles(&all)),
        &canonical(&lonlat, &ply.faces),
        1e-9,
        "GeoJSON (WGS84)",
    );
    // verify transforms back to the raster's CRS.
    verify(&d, &dem, "wgs84.geojson", E, &[]);

    // Asked for: the source CRS with a crs member and a note.
    mesh(&d, &dem, "src.geojson", E, &["--geojson-source-crs"]);
    let path = d.path("src.geojson").to_string_lossy().into_owned();
    let json: Value =
        serde_json::from_slice(&std::fs::read(&path).expect("read")).expect("GeoJSON");
    assert_eq!(
        json["crs"]["properties"]["name"],
        "urn:ogc:def:crs:EPSG::3857"
    );
    assert!(json["tinsmith_note"].as_str().is_some());
    let summary = run("ogrinfo", &["-so", "-al", &path]);
    assert!(summary.contains("ID[\"EPSG\",3857]"), "{summary}");
    let all = run("ogrinfo", &["-al", "-q", &path]);
    assert_same_triangles(
        &canonical_corners(&ogr_triangles(&all)),
        &canonical(&ply.vertices, &ply.faces),
        1e-6,
        "GeoJSON (source CRS)",
    );
    verify(&d, &dem, "src.geojson", E, &[]);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn landxml_parses_as_xml_with_northing_easting_points() {
    let python = venv_python();
    let d = Dir::new();
    let dem = fixture(DEM);
    let report = mesh(&d, &dem, "m.ply", E, &[]);
    let ply = trimesh(&python, &d.path("m.ply"));
    mesh(&d, &dem, "m.xml", E, &[]);
    let script = repo().join("tests/oracles/landxml_read.py");
    let text = run(
        &python.to_string_lossy(),
        &[
            &script.to_string_lossy(),
            &d.path("m.xml").to_string_lossy(),
        ],
    );
    let xml: Value = serde_json::from_str(&text).expect("oracle JSON");
    assert_eq!(xml["points"], report["vertices_after"]);
    assert_eq!(xml["faces"], report["triangles_after"]);
    assert_eq!(xml["surf_type"], "TIN");
    assert_eq!(xml["epsg"], "3857");
    assert_eq!(xml["linear_unit"], "meter");
    assert!(xml["application"].as_str().is_some());
    // Point 1 is the PLY's vertex 0, as northing easting elevation.
    let [x, y, z] = ply.vertices[0];
    assert_eq!(xml["first_point"], serde_json::json!([y, x, z]));
    // The first face, 1-based, is the PLY's first triangle.
    let f = ply.faces[0].map(|i| i + 1);
    assert_eq!(xml["first_face"], serde_json::json!(f));
}

#[test]
fn float32_formats_keep_the_bound_when_heights_do_not_fit_float32() {
    let d = Dir::new();
    // Heights around 100 km (a synthetic field) with digits float32 cannot hold.
    let mut text = String::from(
        "ncols 40\nnrows 30\nxllcorner 500000\nyllcorner 5000000\ncellsize 1\nNODATA_value -9999\n",
    );
    for row in 0..30 {
        let line: Vec<String> = (0..40)
            .map(|col| {
                let z = 100_000.0
                    + f64::from(row * 7 + col * 3) * 1.234_567_89
                    + f64::from((row * col) % 5) * 0.001_234_5;
                format!("{z:.7}")
            })
            .collect();
        text.push_str(&line.join(" "));
        text.push('\n');
    }
    d.write("high.asc", &text);
    // GDAL reads an ASCII grid with decimals as Float32 unless told otherwise.
    let tif = d.path("high.tif").to_string_lossy().into_owned();
    let asc_path = d.path("high.asc").to_string_lossy().into_owned();
    run(
        "gdal_translate",
        &[
            "-q",
            "-oo",
            "DATATYPE=Float64",
            "-ot",
            "Float64",
            "-a_srs",
            "EPSG:32610",
            &asc_path,
            &tif,
        ],
    );
    let asc = tif;
    for ext in ["stl", "glb"] {
        let name = format!("m.{ext}");
        let report = mesh(&d, &asc, &name, "0.001", &[]);
        let rounding = report["float32_height_rounding"]
            .as_f64()
            .expect("rounding");
        assert!(rounding > 0.0, "{ext}: the heights do round");
        assert_eq!(
            report["decimation_max_error"].as_f64().expect("bound"),
            0.001 - rounding
        );
        assert!(report["measured_max_error"].as_f64().expect("measured") <= 0.001);
        // What the file holds, read back, is within the bound.
        verify(&d, &asc, &name, "0.001", &[]);
        // A bound below the rounding cannot be kept in float32: refused, nothing written.
        let o = d.run(&["mesh", &asc, "-o", "tight.stl", "--max-error", "1e-7"]);
        crate::util::assert_fails_naming(&o, &["tight.stl", "float32"]);
        assert!(!d.path("tight.stl").exists());
    }
}

#[test]
fn float32_formats_print_their_origin_tiled_or_not() {
    // docs/guarantee.md (float32 formats): the origin is printed (and in the report); tiled runs used to print nothing.
    let d = Dir::new();
    let dem = fixture(DEM);
    for tile_size in ["4096", "33"] {
        let o = d.run(&[
            "mesh",
            &dem,
            "-o",
            "m.glb",
            "--max-error",
            E,
            "--tile-size",
            tile_size,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("m.glb: float32 positions relative to the local origin ("),
            "tiles of {tile_size}: {}",
            stderr(&o)
        );
    }
}

#[test]
fn stl_and_gltf_from_a_geographic_raster_say_their_positions_are_degrees() {
    // Heights in metres over positions in degrees: true to the raster, but a 3D viewer
    // draws it stretched about 100,000 times, so STL and glTF output says so. GIS formats
    // (and a projected raster, and -q) say nothing.
    let d = Dir::new();
    let geographic = fixture("etopo5_2deg_i16.tif");
    let projected = fixture(DEM);
    for (dem, name, noted) in [
        (&geographic, "g.glb", true),
        (&geographic, "g.stl", true),
        (&geographic, "g.ply", false),
        (&geographic, "g.fgb", false),
        (&projected, "p.glb", false),
    ] {
        let o = d.run(&["mesh", dem, "-o", name, "--max-error", "50"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let said = stderr(&o).contains("degrees");
        assert_eq!(said, noted, "{name}: {}", stderr(&o));
    }
    let o = d.run(&[
        "mesh",
        &geographic,
        "-o",
        "q.glb",
        "--max-error",
        "50",
        "-q",
    ]);
    assert!(
        o.status.success() && stderr(&o).is_empty(),
        "{}",
        stderr(&o)
    );
}

#[test]
fn flags_for_another_format_are_refused_and_format_overrides_the_extension() {
    let d = Dir::new();
    let dem = fixture(DEM);
    for (name, flag) in [
        ("m.ply", "--base"),
        ("m.stl", "--normals"),
        ("m.fgb", "--geojson-source-crs"),
    ] {
        let mut args = vec!["mesh", &dem, "-o", name, "--max-error", E, flag];
        if flag == "--base" {
            args.push("0");
        }
        let o = d.run(&args);
        crate::util::assert_fails_naming(&o, &[name, flag]);
    }
    // A base that is not below the lowest height: refused before any work is written.
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.stl",
        "--max-error",
        E,
        "--base",
        "1e6",
    ]);
    crate::util::assert_fails_naming(&o, &["m.stl", "base"]);
    // Nor one beyond float32 (the floor would be written at -inf).
    for size in ["4096", "16"] {
        let o = d.run(&[
            "mesh",
            &dem,
            "-o",
            "m.stl",
            "--max-error",
            E,
            "--base",
            "-1e40",
            "--tile-size",
            size,
        ]);
        crate::util::assert_fails_naming(&o, &["m.stl", "base", "float32"]);
    }
    assert_eq!(d.files(), Vec::<String>::new(), "nothing written");

    mesh(&d, &dem, "tin.dat", E, &["--format", "fgb"]);
    let summary = run(
        "ogrinfo",
        &["-so", "-al", &d.path("tin.dat").to_string_lossy()],
    );
    assert_eq!(ogr_field(&summary, "Geometry:"), "3D Polygon");
    // Reading it back: the extension says nothing, so `verify` and `contour --mesh` say
    // so and take the format as `mesh` did, from an option.
    let o = d.run(&["verify", &dem, "tin.dat"]);
    assert_fails_naming(&o, &["tin.dat", "extension"]);
    verify(&d, &dem, "tin.dat", E, &["--format", "fgb"]);
    let contour = ["contour", &dem, "-o", "c.geojson", "--interval", "50"];
    let o = d.run(&[&contour[..], &["--mesh", "tin.dat"]].concat());
    assert_fails_naming(&o, &["tin.dat", "extension"]);
    let o = d.run(&[&contour[..], &["--mesh", "tin.dat", "--mesh-format", "fgb"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    // A format that is not the file's is an error naming the file.
    let o = d.run(&["verify", &dem, "tin.dat", "--format", "ply"]);
    assert_fails_naming(&o, &["tin.dat", "PLY"]);
}

#[test]
fn float32_formats_refuse_rasters_too_wide_for_float32_positions() {
    let d = Dir::new();
    // 40,000 samples across: half a float32 step at 20,000 pixels from the origin is more
    // than the verifier's 1e-3 pixel.
    let width = 40_000;
    let row = vec!["1"; width].join(" ");
    let text = format!(
        "ncols {width}\nnrows 2\nxllcorner 500000\nyllcorner 5000000\ncellsize 1\n\
         NODATA_value -9999\n{row}\n{row}\n"
    );
    let asc = d.write("wide.asc", &text).to_string_lossy().into_owned();
    let vrt = d.write(
        "unreadable.vrt",
        &format!(
            "<VRTDataset rasterXSize=\"{width}\" rasterYSize=\"2\">\
             <GeoTransform>500000, 1, 0, 5000000, 0, -1</GeoTransform>\
             <VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource>\
             <SourceFilename relativeToVRT=\"1\">missing.tif</SourceFilename>\
             <SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>"
        ),
    );
    let vrt = vrt.to_string_lossy().into_owned();
    // One tile and many: the untiled and tiled engines make the same check, before
    // decimating, and write nothing.
    for (name, size) in [("w.stl", "40000"), ("w.glb", "40000"), ("w.stl", "1024")] {
        // The VRT's source is missing: refused before reading any sample, since the size
        // alone decides (it said only that reading failed, after trying).
        for input in [&asc, &vrt] {
            let o = d.run(&[
                "mesh",
                input,
                "-o",
                name,
                "--max-error",
                "1",
                "--tile-size",
                size,
            ]);
            crate::util::assert_fails_naming(&o, &[name, "too large for float32"]);
        }
        assert!(!d.path(name).exists());
    }
    // Double-precision formats are fine.
    mesh(&d, &asc, "w.fgb", "1", &["--tile-size", "40000"]);
    verify(&d, &asc, "w.fgb", "1", &[]);
}

#[test]
fn an_inputs_prj_is_never_replaced_by_a_meshs() {
    // An ESRI ASCII grid keeps its CRS in x.prj; OBJ, STL and glTF write their CRS to the
    // .prj beside them. `-o x.obj` would overwrite the input's CRS file: refused. In pixel
    // coordinates no .prj is written, and the input's stays.
    let d = Dir::new();
    d.write(
        "x.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n7 8 9\n",
    );
    let wkt = "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]";
    d.write("x.prj", wkt);
    for out in ["x.obj", "x.stl", "x.glb"] {
        let o = d.run(&["mesh", "x.asc", "-o", out, "--max-error", "0.1"]);
        assert_fails_naming(&o, &[out, "x.prj", "input"]);
    }
    let o = d.run(&[
        "mesh",
        "x.asc",
        "-o",
        "x.stl",
        "--max-error",
        "0.1",
        "--pixel-coords",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(d.path("x.prj")).unwrap(), wkt);
    // Untiled and tiled, a mesh written without a CRS says that the .prj beside it was
    // left as it is (a reader would take it for the mesh's CRS), and leaves it.
    for tile_size in ["512", "2"] {
        let o = d.run(&[
            "mesh",
            "x.asc",
            "-o",
            "x.obj",
            "--max-error",
            "0.1",
            "--pixel-coords",
            "--tile-size",
            tile_size,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let said = stderr(&o);
        assert!(
            said.contains("x.obj: written without a CRS") && said.contains("x.prj"),
            "{said}"
        );
        assert_eq!(std::fs::read_to_string(d.path("x.prj")).unwrap(), wkt);
    }
}

#[test]
fn wgs84_geojson_refuses_triangles_that_fold_around_a_pole() {
    // Antarctic polar stereographic stopping short of the pole: two triangles' straight
    // edges pass around it, and in longitude/latitude they came out wound clockwise,
    // overlapping their neighbours, in a file `verify` passed (it maps back first).
    let d = Dir::new();
    crate::util::south_polar_fixture(&d, "south.tif", "-100000", "90");
    // One triangle, untiled, turns over with a sine of 0.13 (a fold, not a bent sliver).
    let mesh = [
        "mesh",
        "south.tif",
        "-o",
        "m.geojson",
        "--max-error",
        "50",
        "--tile-size",
        "4096",
    ];
    let o = d.run(&mesh);
    let named = [
        "m.geojson",
        "fold over",
        "--geojson-source-crs",
        "--max-edge-length",
    ];
    assert_fails_naming(&o, &named);
    assert!(!d.path("m.geojson").exists());
    // In the raster's CRS the same mesh is written.
    let o = d.run(&[&mesh[..], &["--geojson-source-crs"]].concat());
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
}

#[test]
fn wgs84_geojson_keeps_long_slivers_that_the_projection_bends() {
    // A strip of flat ground with one spike, 30 m pixels at 45 N in UTM 33N: decimation
    // leaves triangles 90 km long and 30-60 m wide, which the projection's curvature turns
    // over in longitude/latitude; the fold check refused the file, blaming a pole.
    let d = Dir::new();
    let (width, height) = (3001usize, 3usize);
    let mut values = vec![0.0f64; width * height];
    values[2 * width + 1500] = 100.0;
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(d.path("strip.raw"), bytes).unwrap();
    d.write(
        "strip.vrt",
        &format!(
            "<VRTDataset rasterXSize=\"{width}\" rasterYSize=\"{height}\"><SRS>EPSG:32633</SRS>\
             <GeoTransform>800000, 30, 0, 5000000, 0, -30</GeoTransform>\
             <VRTRasterBand dataType=\"Float64\" band=\"1\" subClass=\"VRTRawRasterBand\">\
             <SourceFilename relativeToVRT=\"1\">strip.raw</SourceFilename>\
             <ImageOffset>0</ImageOffset><PixelOffset>8</PixelOffset>\
             <LineOffset>{}</LineOffset><ByteOrder>LSB</ByteOrder></VRTRasterBand></VRTDataset>",
            8 * width
        ),
    );
    let o = d.run(&[
        "mesh",
        "strip.vrt",
        "-o",
        "m.geojson",
        "--max-error",
        "1",
        "--tile-size",
        "4096",
    ]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    let v = d.run(&["verify", "strip.vrt", "m.geojson", "--max-error", "1"]);
    assert!(v.status.success(), "{}", crate::util::stdout(&v));
}

#[test]
fn flatgeobuf_that_would_not_fit_in_memory_is_refused_before_writing() {
    // The FlatGeobuf writer takes ~160 bytes a triangle on top of the mesh (its index and
    // reordering); a 36 M-triangle mesh peaked at 6.4 GB and nothing checked it. Noise on a
    // 2000 x 2000 grid at bound 0 keeps ~8 M triangles: ~1.3 GB to write, under a 1.3 GB
    // address-space limit that the decimation itself (~0.3 GB more than its base) fits in.
    let d = Dir::new();
    let (width, height) = (2000usize, 2000usize);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let bytes: Vec<u8> = (0..width * height)
        .flat_map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / 1000.0).to_le_bytes()
        })
        .collect();
    std::fs::write(d.path("noise.raw"), bytes).unwrap();
    d.write(
        "noise.vrt",
        &format!(
            "<VRTDataset rasterXSize=\"{width}\" rasterYSize=\"{height}\">\
             <VRTRasterBand dataType=\"Float32\" band=\"1\" subClass=\"VRTRawRasterBand\">\
             <SourceFilename relativeToVRT=\"1\">noise.raw</SourceFilename>\
             <ImageOffset>0</ImageOffset><PixelOffset>4</PixelOffset>\
             <LineOffset>{}</LineOffset><ByteOrder>LSB</ByteOrder></VRTRasterBand></VRTDataset>",
            4 * width
        ),
    );
    let o = run_under_ulimit(
        &d,
        1_300_000,
        &["mesh", "noise.vrt", "-o", "n.fgb", "--max-error", "0"],
    );
    assert_fails_naming(&o, &["n.fgb", "as FlatGeobuf needs about", ".ply"]);
    assert!(!d.path("n.fgb").exists());
}
