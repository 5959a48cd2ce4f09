//! Several variables over one mesh (`mesh --bands`, `verify --bands`): each band within
//! its bound by the independent verifier, meshes that must coincide do, the PLY read back
//! by trimesh, and every bad input refused with nothing written.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::util::{assert_fails_naming, stderr, stdout, Dir};

pub(crate) const W: usize = 40;
pub(crate) const H: usize = 30;

/// Writes band `name` as ESRI ASCII (`nodata` where `f` gives NaN).
pub(crate) fn write_band(d: &Dir, name: &str, f: impl Fn(usize, usize) -> f64) {
    let mut text = format!(
        "ncols {W}\nnrows {H}\nxllcorner 1000\nyllcorner 2000\ncellsize 10\nNODATA_value -9999\n"
    );
    for y in 0..H {
        let row: Vec<String> = (0..W)
            .map(|x| {
                let v = f(x, y);
                if v.is_nan() {
                    "-9999".to_owned()
                } else {
                    format!("{v}")
                }
            })
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write(name, &text);
}

/// Stacks the named single-band files into `out` as its bands 1, 2, ... (a GeoTIFF,
/// through gdalbuildvrt -separate and gdal_translate).
pub(crate) fn stack(d: &Dir, out: &str, bands: &[&str]) {
    let mut args = vec!["-q", "-separate", "stack.vrt"];
    args.extend_from_slice(bands);
    run_in(d, "gdalbuildvrt", &args);
    run_in(d, "gdal_translate", &["-q", "stack.vrt", out]);
    std::fs::remove_file(d.path("stack.vrt")).expect("remove the VRT");
    for b in bands {
        std::fs::remove_file(d.path(b)).expect("remove a band file");
    }
}

fn run_in(d: &Dir, program: &str, args: &[&str]) -> String {
    let o = Command::new(program)
        .args(args)
        .current_dir(d.path(""))
        .output()
        .unwrap_or_else(|e| panic!("{program} (GDAL) must be on PATH: {e}"));
    assert!(o.status.success(), "{program} {args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Terrain-like fields: smooth waves and a ridge, different per `seed`.
pub(crate) fn field(seed: f64) -> impl Fn(usize, usize) -> f64 {
    move |x, y| {
        let (x, y) = (x as f64, y as f64);
        let z = 50.0 * (0.13 * x + seed).sin() * (0.11 * y - seed).cos()
            + 8.0 * ((0.7 + 0.1 * seed) * x + 0.5 * y).sin()
            + if (x - 2.0 * seed * y).abs() < 3.0 {
                20.0
            } else {
                0.0
            };
        (z * 16.0).round() / 16.0
    }
}

/// `multi.tif`: three different fields.
pub(crate) fn three_bands(d: &Dir) {
    write_band(d, "a.asc", field(0.3));
    write_band(d, "b.asc", field(1.1));
    write_band(d, "c.asc", |x, y| 0.25 * field(2.0)(x, y));
    stack(d, "multi.tif", &["a.asc", "b.asc", "c.asc"]);
}

pub(crate) fn report(d: &Dir) -> Value {
    serde_json::from_slice(&std::fs::read(d.path("r.json")).expect("report")).expect("JSON")
}

pub(crate) fn mesh_ok(d: &Dir, args: &[&str]) -> Value {
    let mut all = vec!["mesh", "multi.tif", "--report", "r.json", "-q"];
    all.extend_from_slice(args);
    let o = d.run(&all);
    assert!(o.status.success(), "mesh {args:?}: {}", stderr(&o));
    report(d)
}

#[test]
fn every_band_within_its_bound_and_verify_checks_each() {
    let d = Dir::new();
    three_bands(&d);
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.ply",
            "--bands",
            "1,2,3",
            "--max-error",
            "1,0.5,0.25",
        ],
    );
    let vars = r["variables"].as_array().expect("variables in the report");
    assert_eq!(vars.len(), 2);
    for (v, (band, bound)) in vars.iter().zip([(2, 0.5), (3, 0.25)]) {
        assert_eq!(v["band"], band);
        assert_eq!(v["name"], format!("band_{band}"));
        assert_eq!(v["max_error"], bound);
        let measured = v["measured_max_error"].as_f64().expect("measured");
        assert!(measured <= bound && measured > 0.0, "{v}");
    }
    assert!(r["measured_max_error"].as_f64().unwrap() <= 1.0);
    // More vertices than the height alone needs at its bound.
    let alone = {
        let o = d.run(&[
            "mesh",
            "multi.tif",
            "-o",
            "h.ply",
            "--max-error",
            "1",
            "--report",
            "h.json",
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let h: Value = serde_json::from_slice(&std::fs::read(d.path("h.json")).unwrap()).unwrap();
        h["triangles_after"].as_u64().unwrap()
    };
    assert!(r["triangles_after"].as_u64().unwrap() > alone, "{r}");

    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2,3",
        "--max-error",
        "1,0.5,0.25",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("band 3 (band_3):"), "{}", stdout(&o));
    // Each band is measured on its own values: a bound below band 3's error fails it.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2,3",
        "--max-error",
        "1,0.5,0.01",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let json: Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    assert_eq!(json["variables"][0]["report"]["max_error_allowed"], 0.5);
    assert!(
        json["variables"][1]["variable"]["measured_max_error"]
            .as_f64()
            .unwrap()
            > 0.01
    );
    // A mesh of the height alone carries no band 2.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "h.ply",
        "--bands",
        "1,2",
        "--max-error",
        "1",
    ]);
    assert_fails_naming(&o, &["h.ply", "band_2"]);
}

#[test]
fn identical_bands_give_the_single_band_mesh() {
    let d = Dir::new();
    write_band(&d, "a.asc", field(0.7));
    write_band(&d, "b.asc", field(0.7));
    stack(&d, "multi.tif", &["a.asc", "b.asc"]);
    // Vertices at their samples (a raised height would differ from its copy).
    let flags = ["--vertex-heights", "samples", "--initial-mesh", "rtin"];
    let mut args = vec!["-o", "one.ply", "--max-error", "0.5"];
    args.extend_from_slice(&flags);
    let one = mesh_ok(&d, &args);
    let mut args = vec!["-o", "two.ply", "--bands", "1,2", "--max-error", "0.5"];
    args.extend_from_slice(&flags);
    let two = mesh_ok(&d, &args);
    assert_eq!(one["triangles_after"], two["triangles_after"]);
    assert_eq!(one["vertices_after"], two["vertices_after"]);
    assert_eq!(one["measured_max_error"], two["measured_max_error"]);
    assert_eq!(
        two["variables"][0]["measured_max_error"],
        one["measured_max_error"]
    );
}

#[test]
fn the_height_band_and_one_bound_for_all() {
    let d = Dir::new();
    three_bands(&d);
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.ply",
            "--bands",
            "1,2,3",
            "--height-band",
            "2",
            "--max-error",
            "0.5",
        ],
    );
    assert_eq!(r["band"], 2);
    let bands: Vec<u64> = r["variables"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["band"].as_u64().unwrap())
        .collect();
    assert_eq!(bands, [1, 3]);
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2,3",
        "--height-band",
        "2",
        "--max-error",
        "0.5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The mesh's z is band 2: checked as band 1's height it fails.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2,3",
        "--max-error",
        "0.5",
    ]);
    assert!(!o.status.success());
}

#[test]
fn nodata_in_one_band_only_shrinks_the_domain() {
    let d = Dir::new();
    write_band(&d, "a.asc", field(0.4));
    let b = field(1.4);
    write_band(&d, "b.asc", |x, y| {
        if (10..16).contains(&x) && (8..12).contains(&y) {
            f64::NAN
        } else {
            b(x, y)
        }
    });
    stack(&d, "multi.tif", &["a.asc", "b.asc"]);
    let r = mesh_ok(&d, &["-o", "m.ply", "--bands", "1,2", "--max-error", "1"]);
    assert_eq!(r["valid_samples"], (W * H - 24) as u64, "{r}");
    // The hole is in the mesh: verified against band 1 alone, its samples are uncovered.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2",
        "--max-error",
        "1",
    ]);
    assert!(o.status.success(), "{}", stdout(&o));
    let o = d.run(&["verify", "multi.tif", "m.ply", "--max-error", "1", "--json"]);
    let json: Value = serde_json::from_str(&stdout(&o)).expect("JSON");
    assert!(json["uncovered_samples"].as_u64().unwrap() > 0, "{json}");
}

#[test]
fn the_same_bytes_for_any_thread_count() {
    let d = Dir::new();
    three_bands(&d);
    let mut bytes = Vec::new();
    for threads in ["1", "2"] {
        let name = format!("m{threads}.ply");
        mesh_ok(
            &d,
            &[
                "-o",
                &name,
                "--bands",
                "1,2,3",
                "--max-error",
                "1,0.5,0.25",
                "--threads",
                threads,
            ],
        );
        bytes.push(std::fs::read(d.path(&name)).unwrap());
    }
    assert_eq!(bytes[0], bytes[1]);
}

#[test]
fn bad_band_lists_and_bounds_are_refused_with_nothing_written() {
    let d = Dir::new();
    three_bands(&d);
    let cases: [(&[&str], &[&str]); 6] = [
        (
            &["--bands", "1,2,3", "--max-error", "1,2"],
            &["multi.tif", "2 bounds for the 3 bands"],
        ),
        (
            &["--bands", "1,2,7", "--max-error", "1"],
            &["multi.tif", "band 7 out of range"],
        ),
        (&["--bands", "1,2", "--max-error", "1,-2"], &["--max-error"]),
        (
            &["--bands", "1,2", "--max-error", "1,NaN"],
            &["--max-error"],
        ),
        (
            &["--bands", "1,2", "--height-band", "3", "--max-error", "1"],
            &["multi.tif", "--height-band 3"],
        ),
        (
            &["--bands", "1,1", "--max-error", "1"],
            &["multi.tif", "twice"],
        ),
    ];
    for (flags, names) in cases {
        let mut args = vec!["mesh", "multi.tif", "-o", "m.ply", "--report", "r.json"];
        args.extend_from_slice(flags);
        let o = d.run(&args);
        assert_fails_naming(&o, names);
        assert_eq!(d.files(), ["multi.tif"], "{flags:?}");
    }
    // Only PLY and glTF carry the variables; count targets are not bounds.
    let o = d.run(&[
        "mesh",
        "multi.tif",
        "-o",
        "m.obj",
        "--bands",
        "1,2",
        "--max-error",
        "1",
    ]);
    assert_fails_naming(&o, &["m.obj", "PLY"]);
    let o = d.run(&[
        "mesh",
        "multi.tif",
        "-o",
        "m.ply",
        "--bands",
        "1,2",
        "--max-triangles",
        "100",
        "--order",
        "greedy",
    ]);
    assert_fails_naming(&o, &["multi.tif", "--max-triangles"]);
    assert_eq!(d.files(), ["multi.tif"]);
}

#[test]
fn the_papers_bounds_model_keeps_every_band_within_its_bound() {
    let d = Dir::new();
    three_bands(&d);
    for start in ["full", "auto"] {
        let r = mesh_ok(
            &d,
            &[
                "-o",
                "m.ply",
                "--bands",
                "1,2,3",
                "--max-error",
                "8,8,2",
                "--error-model",
                "bounds",
                "--initial-mesh",
                start,
            ],
        );
        assert_eq!(r["error_model"], "bounds", "{r}");
        for v in r["variables"].as_array().unwrap() {
            let measured = v["measured_max_error"].as_f64().unwrap();
            assert!(
                measured <= v["max_error"].as_f64().unwrap() && measured > 0.0,
                "{v}"
            );
        }
        // Decimated, and checked again from the file by the verifier.
        assert!(r["decimation_percent"].as_f64().unwrap() > 10.0, "{r}");
        let o = d.run(&[
            "verify",
            "multi.tif",
            "m.ply",
            "--bands",
            "1,2,3",
            "--max-error",
            "8,8,2",
        ]);
        assert!(o.status.success(), "{} {}", stdout(&o), stderr(&o));
    }
}

#[test]
#[ignore = "needs trimesh in .venv (make deps)"]
fn trimesh_reads_one_property_per_band() {
    let d = Dir::new();
    three_bands(&d);
    mesh_ok(
        &d,
        &[
            "-o",
            "m.ply",
            "--bands",
            "1,2,3",
            "--max-error",
            "1,0.5,0.25",
            "--pixel-coords",
        ],
    );
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracles/ply_properties.py");
    let o = Command::new(crate::util::venv_python())
        .arg(&script)
        .arg(d.path("m.ply"))
        .output()
        .expect("python runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let json: Value = serde_json::from_slice(&o.stdout).expect("oracle JSON");
    assert_eq!(
        json["names"],
        serde_json::json!(["x", "y", "z", "band_2", "band_3"])
    );
    // Pixel coordinates: each vertex's properties are its bands' samples there.
    let c = &json["columns"];
    let at = |name: &str, i: usize| c[name][i].as_f64().unwrap();
    let n = c["x"].as_array().unwrap().len();
    assert!(n > 4 && !json["faces"].as_array().unwrap().is_empty());
    for i in 0..n {
        let (x, y) = (at("x", i) as usize, at("y", i) as usize);
        assert_eq!(at("band_2", i), field(1.1)(x, y), "vertex {i}");
        assert_eq!(at("band_3", i), 0.25 * field(2.0)(x, y), "vertex {i}");
    }
}

#[test]
#[ignore = "needs the Khronos glTF validator in .tools (make deps)"]
fn gltf_carries_each_band_as_an_attribute_the_validator_accepts() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let modules = std::env::var_os("TINSMITH_NODE_MODULES")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo.join(".tools/node_modules"));
    assert!(
        modules.join("gltf-validator").exists(),
        "oracle missing: gltf-validator in .tools/node_modules; run `make deps`"
    );
    let d = Dir::new();
    three_bands(&d);
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.glb",
            "--bands",
            "1,2,3",
            "--max-error",
            "1,0.5,0.25",
            "--normals",
        ],
    );
    assert_eq!(r["variables"].as_array().unwrap().len(), 2);
    let script = repo.join("tests/oracles/gltf_validate.js");
    let o = Command::new("node")
        .arg(&script)
        .arg(d.path("m.glb"))
        .output()
        .expect("node runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value = serde_json::from_slice(&o.stdout).expect("validator JSON");
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    assert_eq!(report["issues"]["numWarnings"], 0, "{report:#}");
    // Read back: each band against its float32 attribute.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.glb",
        "--bands",
        "1,2,3",
        "--max-error",
        "1,0.5,0.25",
    ]);
    assert!(o.status.success(), "{} {}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("band 2 (band_2)"), "{}", stdout(&o));
    // Tiled: the welded mesh's bands, as valid.
    mesh_ok(
        &d,
        &[
            "-o",
            "t.glb",
            "--bands",
            "1,2,3",
            "--max-error",
            "1,0.5,0.25",
            "--tile-size",
            "16",
        ],
    );
    let o = Command::new("node")
        .arg(&script)
        .arg(d.path("t.glb"))
        .output()
        .expect("node runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value = serde_json::from_slice(&o.stdout).expect("validator JSON");
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
}

#[test]
fn geojson_and_flatgeobuf_carry_each_triangles_corner_means_as_gdal_reads_them() {
    let d = Dir::new();
    three_bands(&d);
    for name in ["m.geojson", "m.fgb"] {
        mesh_ok(
            &d,
            &[
                "-o",
                name,
                "--bands",
                "1,2,3",
                "--max-error",
                "1,0.5,0.25",
                "--pixel-coords",
            ],
        );
        // GDAL reads the file (an independent reader) and writes it as GeoJSON.
        let text = run_in(&d, "ogr2ogr", &["-f", "GeoJSON", "/vsistdout/", name]);
        let json: Value = serde_json::from_str(&text).expect("GeoJSON from ogr2ogr");
        let features = json["features"].as_array().expect("features");
        assert!(features.len() > 10, "{name}");
        for f in features {
            let ring = f["geometry"]["coordinates"][0].as_array().expect("ring");
            let corners: Vec<(usize, usize)> = ring[..3]
                .iter()
                .map(|p| {
                    (
                        p[0].as_f64().unwrap() as usize,
                        p[1].as_f64().unwrap() as usize,
                    )
                })
                .collect();
            for (band, field) in [("band_2", field(1.1)), ("band_3", field(2.0))] {
                let scale = if band == "band_3" { 0.25 } else { 1.0 };
                let sum: f64 = corners.iter().map(|&(x, y)| scale * field(x, y)).sum();
                let got = f["properties"][band].as_f64().expect("a mean per band");
                assert!(
                    (got - sum / 3.0).abs() <= 1e-12 * sum.abs().max(1.0),
                    "{name} {f}"
                );
            }
        }
    }
}

/// Writes band `name` as ESRI ASCII with its lower-left corner at `(x0, y0)` and cells of
/// `cell`.
pub(crate) fn write_band_at(
    d: &Dir,
    name: &str,
    (x0, y0, cell): (f64, f64, f64),
    f: impl Fn(usize, usize) -> f64,
) {
    let mut text = format!(
        "ncols {W}\nnrows {H}\nxllcorner {x0}\nyllcorner {y0}\ncellsize {cell}\nNODATA_value -9999\n"
    );
    for y in 0..H {
        let row: Vec<String> = (0..W).map(|x| format!("{}", f(x, y))).collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write(name, &text);
}

#[test]
fn attributes_from_another_raster_on_the_same_grid() {
    let d = Dir::new();
    write_band(&d, "dem.asc", field(0.3));
    write_band(&d, "other.asc", field(1.7));
    let r = {
        let o = d.run(&[
            "mesh",
            "dem.asc",
            "-o",
            "m.ply",
            "--max-error",
            "1",
            "--attributes",
            "other.asc",
            "--attribute-error",
            "0.5",
            "--report",
            "r.json",
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        report(&d)
    };
    assert_eq!(r["variables"][0]["name"], "other_band_1", "{r}");
    assert!(r["variables"][0]["measured_max_error"].as_f64().unwrap() <= 0.5);
    let o = d.run(&[
        "verify",
        "dem.asc",
        "m.ply",
        "--max-error",
        "1",
        "--attributes",
        "other.asc:1",
        "--attribute-error",
        "0.5",
    ]);
    assert!(o.status.success(), "{} {}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("(other_band_1)"), "{}", stdout(&o));

    // Elsewhere: refused, naming the file, nothing written.
    write_band_at(&d, "far.asc", (90_000.0, 2000.0, 10.0), field(1.0));
    let o = d.run(&[
        "mesh",
        "dem.asc",
        "-o",
        "n.ply",
        "--max-error",
        "1",
        "--attributes",
        "far.asc",
        "--attribute-error",
        "0.5",
    ]);
    assert_fails_naming(&o, &["far.asc", "does not overlap"]);
    assert!(!d.path("n.ply").exists());

    // A band list that is not one, or lists a band twice: said so, not "no such file".
    for (spec, problem) in [
        ("other.asc:1,x", "comma-separated list of band numbers"),
        ("other.asc:", "comma-separated list of band numbers"),
        ("other.asc:1,1", "lists band 1 twice"),
    ] {
        let o = d.run(&[
            "mesh",
            "dem.asc",
            "-o",
            "n.ply",
            "--max-error",
            "1",
            "--attributes",
            spec,
            "--attribute-error",
            "0.5",
        ]);
        assert_fails_naming(&o, &["other.asc", problem]);
        assert!(!d.path("n.ply").exists());
    }
}

#[test]
fn attributes_on_another_grid_are_resampled_as_gdalwarp_resamples_them() {
    let d = Dir::new();
    write_band(&d, "dem.asc", field(0.3));
    // Half the cell size, shifted by a third of a cell: no sample on the DEM's grid.
    write_band_at(&d, "finer.asc", (1003.0, 2000.0, 5.0), field(1.7));
    let dem = tinsmith_raster::open_info(&d.path("dem.asc"), 1).unwrap();
    let g = dem.geo_transform.unwrap();
    let (x0, y1) = (g[0], g[3]);
    let (x1, y0) = (
        x0 + g[1] * f64::from(dem.width),
        y1 + g[5] * f64::from(dem.height),
    );
    for method in ["bilinear", "nearest", "cubic", "average"] {
        // The same values as the gdalwarp command line puts on the DEM's grid, in a file
        // of the same name (the PLY property is named after it) in another directory.
        std::fs::create_dir_all(d.path(method)).unwrap();
        let warped = format!("{method}/finer.tif");
        let gdal_method = if method == "nearest" { "near" } else { method };
        run_in(
            &d,
            "gdalwarp",
            &[
                "-q",
                "-te",
                &x0.to_string(),
                &y0.to_string(),
                &x1.to_string(),
                &y1.to_string(),
                "-ts",
                &dem.width.to_string(),
                &dem.height.to_string(),
                "-r",
                gdal_method,
                "-ot",
                "Float64",
                "-dstnodata",
                "nan",
                "finer.asc",
                &warped,
            ],
        );
        let mesh = |attributes: &str, out: &str| {
            let o = d.run(&[
                "mesh",
                "dem.asc",
                "-o",
                out,
                "--max-error",
                "1",
                "--attributes",
                attributes,
                "--attribute-error",
                "0.5",
                "--attribute-resampling",
                method,
                "--report",
                "r.json",
                "-q",
            ]);
            assert!(o.status.success(), "{method} {attributes}: {}", stderr(&o));
            report(&d)
        };
        let r = mesh("finer.asc", "resampled.ply");
        assert_eq!(r["variables"][0]["resampled"], method, "{r}");
        assert!(
            r["variables"][0]["measured_max_error"].as_f64().unwrap() <= 0.5,
            "{r}"
        );
        let r = mesh(&warped, "warped.ply");
        assert!(r["variables"][0].get("resampled").is_none(), "{r}");
        assert_eq!(
            std::fs::read(d.path("resampled.ply")).unwrap(),
            std::fs::read(d.path("warped.ply")).unwrap(),
            "{method}: the mesh differs from the one on gdalwarp's values"
        );
        // verify resamples the same way, and measures the band against those values.
        let o = d.run(&[
            "verify",
            "dem.asc",
            "resampled.ply",
            "--max-error",
            "1",
            "--attributes",
            "finer.asc",
            "--attribute-error",
            "0.5",
            "--attribute-resampling",
            method,
        ]);
        assert!(o.status.success(), "{} {}", stdout(&o), stderr(&o));
    }
    // The resampled copy is written under TMPDIR, and gone when the run ends.
    std::fs::create_dir_all(d.path("scratch")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args([
            "mesh",
            "dem.asc",
            "-o",
            "t.ply",
            "--max-error",
            "1",
            "--attributes",
        ])
        .args([
            "finer.asc",
            "--attribute-error",
            "0.5",
            "--tile-size",
            "16",
            "-q",
        ])
        .env("TMPDIR", d.path("scratch"))
        .current_dir(d.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(d.path("scratch")).unwrap().count(), 0);
    let o = d.run(&[
        "mesh",
        "dem.asc",
        "-o",
        "n.ply",
        "--max-error",
        "1",
        "--attributes",
        "other.asc:1",
        "--attribute-error",
        "0.5,0.5",
    ]);
    assert_fails_naming(&o, &["other.asc", "2 bounds for 1 bands"]);
}

/// `rgb.tif`: an 8-bit height and three 8-bit colour bands.
fn height_and_colours(d: &Dir) -> [fn(usize, usize) -> f64; 4] {
    let bands: [fn(usize, usize) -> f64; 4] = [
        |x, y| ((x * 3 + y * 2) % 200) as f64 + if x > 20 { 30.0 } else { 0.0 },
        |x, _| (x * 6) as f64,
        |_, y| (y * 8) as f64,
        |x, y| {
            if (x / 8 + y / 8) % 2 == 0 {
                250.0
            } else {
                10.0
            }
        },
    ];
    for (i, f) in bands.iter().enumerate() {
        write_band(d, &format!("c{i}.asc"), f);
    }
    run_in(
        d,
        "gdalbuildvrt",
        &[
            "-q",
            "-separate",
            "stack.vrt",
            "c0.asc",
            "c1.asc",
            "c2.asc",
            "c3.asc",
        ],
    );
    run_in(
        d,
        "gdal_translate",
        &["-q", "-ot", "Byte", "stack.vrt", "rgb.tif"],
    );
    bands
}

#[test]
#[ignore = "needs trimesh in .venv and the glTF validator in .tools (make deps)"]
fn three_8_bit_bands_are_vertex_colours_in_ply_obj_and_gltf() {
    let d = Dir::new();
    let bands = height_and_colours(&d);
    for name in ["c.ply", "c.obj", "c.glb"] {
        let o = d.run(&[
            "mesh",
            "rgb.tif",
            "-o",
            name,
            "--bands",
            "1,2,3,4",
            "--max-error",
            "2,8,8,8",
            "--pixel-coords",
            "-q",
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracles/vertex_colours.py");
        let o = Command::new(crate::util::venv_python())
            .arg(&script)
            .arg(d.path(name))
            .output()
            .expect("python runs");
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let json: Value = serde_json::from_slice(&o.stdout).expect("oracle JSON");
        let vertices = json["vertices"].as_array().unwrap();
        assert!(vertices.len() > 10, "{name}");
        for (v, c) in vertices.iter().zip(json["colours"].as_array().unwrap()) {
            let (x, y) = (
                v[0].as_f64().unwrap().round() as usize,
                v[1].as_f64().unwrap().round() as usize,
            );
            let expected: Vec<u64> = bands[1..].iter().map(|f| f(x, y) as u64).collect();
            let got: Vec<u64> = (0..3).map(|k| c[k].as_u64().unwrap()).collect();
            assert_eq!(got, expected, "{name} at ({x}, {y})");
        }
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracles/gltf_validate.js");
    let o = Command::new("node")
        .arg(&script)
        .arg(d.path("c.glb"))
        .output()
        .expect("node runs");
    let report: Value = serde_json::from_slice(&o.stdout).expect("validator JSON");
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    assert_eq!(report["issues"]["numWarnings"], 0, "{report:#}");
    // The PLY and the glTF keep each band too: verify reads them back.
    for name in ["c.ply", "c.glb"] {
        let o = d.run(&[
            "verify",
            "rgb.tif",
            name,
            "--bands",
            "1,2,3,4",
            "--max-error",
            "2,8,8,8",
            "--pixel-coords",
        ]);
        assert!(o.status.success(), "{name}: {} {}", stdout(&o), stderr(&o));
    }
}

#[test]
fn an_orthophoto_on_another_grid_stays_colours_when_resampled_by_nearest() {
    let d = Dir::new();
    write_band(&d, "dem.asc", field(0.3));
    // Three 8-bit bands at two thirds of the DEM's cell size, shifted: another grid.
    for (name, seed) in [("r.asc", 0.5), ("g.asc", 1.5), ("b.asc", 2.5)] {
        write_band_at(&d, name, (1001.0, 2001.0, 10.0 * 2.0 / 3.0), |x, y| {
            (field(seed)(x, y).abs() * 2.0).round().min(255.0)
        });
    }
    stack(&d, "rgb_f.tif", &["r.asc", "g.asc", "b.asc"]);
    run_in(
        &d,
        "gdal_translate",
        &["-q", "-ot", "Byte", "rgb_f.tif", "rgb.tif"],
    );
    let header = |out: &str| {
        let bytes = std::fs::read(d.path(out)).unwrap();
        let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
        String::from_utf8_lossy(&bytes[..end]).into_owned()
    };
    for (method, colours) in [("nearest", true), ("bilinear", false)] {
        let out = format!("{method}.ply");
        let o = d.run(&[
            "mesh",
            "dem.asc",
            "-o",
            &out,
            "--max-error",
            "1",
            "--attributes",
            "rgb.tif",
            "--attribute-error",
            "8",
            "--attribute-resampling",
            method,
            "-q",
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        let h = header(&out);
        // Nearest keeps the bytes, so they are colours too; bilinear makes other numbers.
        assert_eq!(h.contains("property uchar red"), colours, "{method}: {h}");
        assert!(h.contains("property double rgb_band_3"), "{method}: {h}");
    }
}
