//! `tinsmith mesh` then `tinsmith verify` on real rasters, in every coordinate mode.

use crate::util::{fixture, stderr, stdout, Dir};

/// Meshes `input` at `e` and verifies the written file independently; returns the report.
fn mesh_then_verify(input: &str, e: f64, extra: &[&str], ext: &str) -> serde_json::Value {
    let d = Dir::new();
    let out = format!("out.{ext}");
    let es = e.to_string();
    let mut args = vec![
        "mesh",
        input,
        "-o",
        &out,
        "--max-error",
        &es,
        "--report",
        "r.json",
    ];
    args.extend_from_slice(extra);
    let o = d.run(&args);
    assert!(
        o.status.success(),
        "mesh failed: {}",
        crate::util::stderr(&o)
    );
    let mut vargs = vec!["verify", input, &out, "--max-error", &es, "--json"];
    if extra.contains(&"--pixel-coords") {
        vargs.push("--pixel-coords");
    }
    let v = d.run(&vargs);
    let json: serde_json::Value = serde_json::from_str(&stdout(&v)).expect("verify --json");
    assert!(v.status.success(), "verify failed: {json:#}");
    assert!(json["max_error"].as_f64().unwrap() <= e);
    assert_eq!(json["uncovered_samples"], 0);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    assert_eq!(report["triangles_after"], json["triangles"]);
    assert_eq!(report["measured_max_error"], json["max_error"]);
    assert_eq!(report["isolated_samples"], json["isolated_samples"]);
    report
}

#[test]
fn float32_dem_with_flt_max_nodata() {
    let r = mesh_then_verify(&fixture("tintn_valid_raster_3857.tif"), 0.5, &[], "ply");
    assert_eq!(r["width"], 100);
    assert!(r["triangles_after"].as_u64().unwrap() < r["triangles_before"].as_u64().unwrap());
}

#[test]
fn ascii_grid_with_zero_nodata_as_obj() {
    mesh_then_verify(&fixture("landlab_west_bijou_gully.asc"), 0.25, &[], "obj");
}

#[test]
fn sample_dem_in_pixel_coordinates() {
    mesh_then_verify(
        &fixture("becmodel_dem_bc_albers_50m.tif"),
        10.0,
        &["--pixel-coords"],
        "ply",
    );
}

#[test]
fn image_without_geotransform_each_selection() {
    let heart = fixture("mr_heart_256x256_u8_frame07.png");
    for sel in ["hybrid", "min-error", "min-introduced"] {
        let r = mesh_then_verify(&heart, 8.0, &["--selection", sel], "ply");
        assert!(
            r["decimation_percent"].as_f64().unwrap() > 30.0,
            "{sel}: {r}"
        );
    }
}

#[test]
fn signed_ct_slice_at_the_papers_bounds() {
    let ct = fixture("ct_brain_crop_128_i16.tif");
    let mut last = 0.0;
    for e in [2.0, 20.0, 100.0, 1000.0] {
        let r = mesh_then_verify(&ct, e, &[], "ply");
        let pct = r["decimation_percent"].as_f64().unwrap();
        assert!(
            pct > last,
            "decimation should grow with the bound: {pct} at {e}"
        );
        last = pct;
    }
}

#[test]
fn ascii_grid_half_nodata_watershed() {
    let r = mesh_then_verify(&fixture("landlab_hugo_site.asc"), 0.5, &[], "ply");
    assert_eq!(r["valid_samples"], 2152);
    // Two valid samples touch no valid cell: the mesh says so, and so does verify.
    assert_eq!(r["isolated_samples"], 2);
    let d = Dir::new();
    let dem = fixture("landlab_hugo_site.asc");
    let o = d.run(&["mesh", &dem, "-o", "m.ply", "--max-error", "0.5"]);
    assert!(crate::util::stderr(&o).contains("2 valid samples are in no 2x2 block"));
    let v = d.run(&["verify", &dem, "m.ply"]);
    assert!(
        stdout(&v).contains("isolated:        2 valid samples"),
        "{}",
        stdout(&v)
    );
}

#[test]
fn same_input_same_bytes() {
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    for name in ["a.ply", "b.ply"] {
        assert!(d
            .run(&["mesh", &dem, "-o", name, "--max-error", "1"])
            .status
            .success());
    }
    assert_eq!(
        std::fs::read(d.path("a.ply")).unwrap(),
        std::fs::read(d.path("b.ply")).unwrap()
    );
}

#[test]
fn verify_rejects_a_mesh_beyond_the_bound() {
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    assert!(d
        .run(&["mesh", &dem, "-o", "m.ply", "--max-error", "2"])
        .status
        .success());
    let o = d.run(&["verify", &dem, "m.ply", "--max-error", "0.01"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("FAIL"));
}

#[test]
fn verify_measures_the_mesh_as_written_not_moved_onto_the_samples() {
    // The centre sample stands 1000 above the rest. With the centre vertex 0.0009 pixel
    // off (or a corner vertex, leaving its sample uncovered) the mesh breaks the bound,
    // but verify moved vertices within 0.001 pixel onto their samples and passed it. In an
    // f64 format only rounding-sized offsets are taken for their samples now.
    let d = Dir::new();
    let asc = d.write(
        "g.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n\
         0 0 0\n0 1000 0\n0 0 0\n",
    );
    let asc = asc.to_str().unwrap();
    let mesh = |dx: [f64; 2]| {
        let mut v = String::new();
        for (i, (x, y)) in (0..3).flat_map(|y| (0..3).map(move |x| (x, y))).enumerate() {
            let z = if (x, y) == (1, 1) { 1000 } else { 0 };
            let shift = if i == 4 {
                dx[0]
            } else if i == 0 {
                dx[1]
            } else {
                0.0
            };
            v += &format!("v {} {} {z}\n", f64::from(x) + shift, f64::from(y));
        }
        // Two triangles per cell, as verify expects them in (column, row) coordinates.
        for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let a = 1 + x + 3 * y;
            v += &format!("f {a} {} {}\nf {a} {} {}\n", a + 1, a + 4, a + 4, a + 3);
        }
        v
    };
    for (dx, code) in [
        ([0.0, 0.0], 0),
        ([1e-9, 1e-9], 0),
        ([0.0009, 0.0], 2),
        ([0.0, 0.0009], 2),
    ] {
        d.write("m.obj", &mesh(dx));
        let o = d.run(&[
            "verify",
            asc,
            "m.obj",
            "--pixel-coords",
            "--max-error",
            "0.5",
        ]);
        assert_eq!(
            o.status.code(),
            Some(code),
            "{dx:?}: {}{}",
            stdout(&o),
            stderr(&o)
        );
        if code == 2 {
            assert!(
                stderr(&o).contains("9.0e-4 pixel off the sample centre"),
                "{}",
                stderr(&o)
            );
        }
    }
}

#[test]
fn verify_rejects_a_mesh_with_a_hole() {
    // A 3x3 grid meshed by hand with one triangle missing.
    let d = Dir::new();
    let asc = d.write(
        "g.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 1 1\n1 1 1\n1 1 1\n",
    );
    d.write("m.obj", "v 0 0 1\nv 2 0 1\nv 2 2 1\nv 0 2 1\nf 1 2 3\n");
    let o = d.run(&["verify", asc.to_str().unwrap(), "m.obj", "--pixel-coords"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("NO"), "{}", stdout(&o));
}

#[test]
fn info_reports_nodata_and_crs() {
    let d = Dir::new();
    let o = d.run(&[
        "info",
        &fixture("tintn_valid_raster_3857.tif"),
        "--json",
        "-q",
    ]);
    assert!(o.status.success());
    let j: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["width"], 100);
    assert_eq!(j["height"], 80);
    assert_eq!(j["nodata_samples"], 970);
    assert_eq!(j["epsg"], 3857);
    // A NaN nodata is a string in JSON (a NaN number would be null, "none declared").
    d.write(
        "nan.asc",
        "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value nan\n1 2\n3 4\n",
    );
    let o = d.run(&["info", "nan.asc", "--json", "-q"]);
    let j: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["nodata"], "NaN");
}

#[test]
fn quiet_mesh_prints_nothing_and_report_has_every_phase() {
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.obj",
        "--max-error",
        "1",
        "-q",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success());
    assert_eq!(crate::util::stderr(&o), "");
    #[cfg(unix)]
    {
        // Readable by others as the umask allows, like the mesh (not tempfile's 0600).
        use std::os::unix::fs::PermissionsExt;
        let mode = |name: &str| {
            std::fs::metadata(d.path(name))
                .unwrap()
                .permissions()
                .mode()
        };
        assert_eq!(mode("r.json") & 0o777, mode("m.obj") & 0o777);
    }
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    for phase in [
        "read",
        "initial_mesh",
        "decimate",
        "verify",
        "write",
        "total",
    ] {
        assert!(r["seconds"][phase].as_f64().unwrap() >= 0.0, "{phase}");
    }
    assert_eq!(r["valid_samples"], 8000 - 970);
    assert_eq!(r["max_error"], 1.0);
    let pct = r["decimation_percent"].as_f64().unwrap();
    let (before, after) = (
        r["triangles_before"].as_f64().unwrap(),
        r["triangles_after"].as_f64().unwrap(),
    );
    assert!((pct - 100.0 * (1.0 - after / before)).abs() < 1e-9);
    // OBJ gets the raster's CRS in a .prj sidecar.
    assert_eq!(d.files(), vec!["m.obj", "m.prj", "r.json"]);
}

#[test]
fn every_model_order_and_retriangulation_from_the_cli() {
    let ct = fixture("ct_brain_crop_128_i16.tif");
    for model in ["bounds", "exact"] {
        for order in ["sweep", "greedy"] {
            for re in ["ears", "dp"] {
                let extra = [
                    "--error-model",
                    model,
                    "--order",
                    order,
                    "--retriangulate",
                    re,
                ];
                let r = mesh_then_verify(&ct, 20.0, &extra, "ply");
                assert_eq!(r["error_model"], model);
                assert_eq!(r["order"], order);
                assert_eq!(r["retriangulate"], re);
            }
        }
    }
}

#[test]
fn the_report_records_every_decimation_option() {
    // --flip-rounds, --extend-rounds, --dp-max-ring, the contour levels and --pixel-coords
    // were left out of the report.
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.ply",
        "--max-error",
        "2",
        "--flip-rounds",
        "1",
        "--extend-rounds",
        "2",
        "--dp-max-ring",
        "6",
        "--contour-interval",
        "50",
        "--contour-offset",
        "5",
        "--pixel-coords",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    assert_eq!(r["flip_rounds"], 1);
    assert_eq!(r["extend_rounds"], 2);
    assert_eq!(r["dp_max_ring"], 6);
    assert_eq!(r["contour_interval"], 50.0);
    assert_eq!(r["contour_offset"], 5.0);
    assert_eq!(r["contour_levels"], serde_json::json!([]));
    assert_eq!(r["pixel_coords"], true);
}

#[test]
fn both_count_targets_are_met() {
    // With both, decimation stopped at the first count reached (100 vertices, 170
    // triangles) and the note blamed the domain's outline for the triangles.
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.ply",
        "--max-triangles",
        "60",
        "--max-vertices",
        "100",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    assert!(
        !crate::util::stderr(&o).contains("note"),
        "{}",
        crate::util::stderr(&o)
    );
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    assert!(r["triangles_after"].as_u64().unwrap() <= 60, "{r}");
    assert!(r["vertices_after"].as_u64().unwrap() <= 100, "{r}");
}

#[test]
fn a_bound_far_beyond_the_relief_keeps_heights_on_the_data() {
    // Heights of 26.6 to 44.1, with nodata holes whose outlines keep inner vertices:
    // --max-error 1e308 raised them to 5.96e300 (PLY, OBJ, GeoJSON), and from 1e46 the
    // raise overflowed float32, so STL and glTF failed their own verification with an
    // internal error printing a 309-digit number.
    let dem = fixture("tintn_valid_raster_3857.tif");
    let raster = tinsmith_raster::read_samples(std::path::Path::new(&dem), 1).expect("raster");
    let (lo, hi) = (raster.info.min.expect("min"), raster.info.max.expect("max"));
    let d = Dir::new();
    for (ext, bound) in [
        ("ply", "1e308"),
        ("obj", "1e308"),
        ("geojson", "1e308"),
        ("stl", "1e46"),
        ("glb", "1e46"),
        ("stl", "1e308"),
        ("glb", "1e308"),
    ] {
        let out = format!("m.{ext}");
        let o = d.run(&["mesh", &dem, "-o", &out, "--max-error", bound]);
        let err = stderr(&o);
        assert!(o.status.success(), "{out} at {bound}: {err}");
        assert!(!err.contains("0000000000"), "{err}");
        let mesh = tinsmith_formats::read_mesh(&d.path(&out)).expect("mesh");
        for v in &mesh.vertices {
            assert!(
                v[2] >= lo - 1e-3 && v[2] <= hi + 1e-3,
                "{out} at {bound}: height {} outside {lo}..{hi}",
                v[2]
            );
        }
        let v = d.run(&["verify", &dem, &out, "--max-error", bound]);
        assert!(v.status.success(), "{}", stdout(&v));
    }
}

#[test]
fn heights_far_from_zero_say_how_much_of_the_bound_is_left() {
    // At 1e12 the rounding margin (2^-40 of the largest |height|) took 0.9 of a bound of 1
    // and nothing said so: far fewer triangles went than the bound allowed.
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    d.write(
        "far.vrt",
        &format!(
            "<VRTDataset rasterXSize=\"430\" rasterYSize=\"516\"><VRTRasterBand \
             dataType=\"Float64\" band=\"1\"><Offset>1e12</Offset><SimpleSource>\
             <SourceFilename>{dem}</SourceFilename><SourceBand>1</SourceBand>\
             </SimpleSource></VRTRasterBand></VRTDataset>"
        ),
    );
    for input in ["far.vrt", dem.as_str()] {
        let o = d.run(&["mesh", input, "-o", "m.ply", "--max-error", "1"]);
        assert!(o.status.success(), "{}", crate::util::stderr(&o));
        let noted = crate::util::stderr(&o).contains("margin for rounding");
        assert_eq!(noted, input == "far.vrt", "{}", crate::util::stderr(&o));
    }
}

#[test]
fn max_triangles_reports_the_verified_error() {
    let d = Dir::new();
    let dem = fixture("tintn_valid_raster_3857.tif");
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.ply",
        "--max-triangles",
        "500",
        "--error-model",
        "exact",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    let after = r["triangles_after"].as_u64().unwrap();
    assert!((490..=500).contains(&after), "{after}");
    assert!(r["max_error"].is_null());
    // A count target runs in greedy order whatever --order says; the report said "sweep".
    assert_eq!(r["order"], "greedy");
    let measured = r["measured_max_error"].as_f64().unwrap();
    // The file verifies at the measured error and not below it.
    let m = measured.to_string();
    assert!(d
        .run(&["verify", &dem, "m.ply", "--max-error", &m])
        .status
        .success());
    let below = (measured * 0.999).to_string();
    assert_eq!(
        d.run(&["verify", &dem, "m.ply", "--max-error", &below])
            .status
            .code(),
        Some(1)
    );
}

#[test]
fn max_edge_length_caps_every_edge_untiled_and_tiled() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    for tile_size in ["100000", "64"] {
        let extra = [
            "--pixel-coords",
            "--max-edge-length",
            "6",
            "--tile-size",
            tile_size,
        ];
        mesh_then_verify(&dem, 20.0, &extra, "ply");
        let d = Dir::new();
        let mut args = vec!["mesh", &dem, "-o", "m.ply", "--max-error", "20", "-q"];
        args.extend_from_slice(&extra);
        assert!(d.run(&args).status.success());
        let mesh = tinsmith_formats::read_mesh(&d.path("m.ply")).expect("mesh");
        let longest = mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| {
                let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
                (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
            })
            .fold(0.0f64, f64::max);
        assert!(
            longest <= 36.0,
            "--tile-size {tile_size}: an edge of squared length {longest}"
        );
        assert!(longest >= 16.0, "the cap should bind on this DEM at 20 m");
    }
}

#[test]
fn a_scaling_vrt_is_read_as_its_band_type_holds_it() {
    // GDAL hands out a VRT's scaled values unrounded when asked for f64; the band's own
    // type (what gdal_translate writes, what rasterio reads) rounds them. The mesh must
    // hold the band's values: verified at 0 against GDAL's own GeoTIFF copy of the VRT.
    let d = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    for (ty, scale_to) in [
        ("Int16", "1000.7"),
        ("UInt32", "70000.3"),
        ("Int64", "70000.3"),
        ("Float32", "1000.7"),
    ] {
        let vrt = format!("{ty}.vrt");
        let tif = format!("{ty}.tif");
        let scaling = [
            "-of", "VRT", "-ot", ty, "-scale_1", "350", "2583", "0", scale_to, "-srcwin", "0", "0",
            "120", "90", &input, &vrt,
        ];
        for args in [&scaling[..], &["-of", "GTiff", &vrt, &tif]] {
            let o = std::process::Command::new("gdal_translate")
                .current_dir(d.path(""))
                .arg("-q")
                .args(args)
                .output()
                .expect("gdal_translate (Debian gdal-bin) must be on PATH");
            assert!(o.status.success(), "{}", crate::util::stderr(&o));
        }
        let mesh = format!("{ty}.ply");
        let o = d.run(&["mesh", &vrt, "-o", &mesh, "--max-error", "0", "-q"]);
        assert!(o.status.success(), "{}", crate::util::stderr(&o));
        let v = d.run(&["verify", &tif, &mesh, "--max-error", "0"]);
        assert!(v.status.success(), "{ty}: {}", stdout(&v));
    }
}

#[test]
fn raised_vertex_heights_keep_fewer_triangles_on_integer_heights() {
    // The sample DEM is Int16: at a bound of half a unit, many candidate triangles have a
    // sample exactly the bound from their plane; raised heights (the default) let the
    // half with the sample above pass.
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let untiled = ["--tile-size", "1024"];
    let raised = mesh_then_verify(&dem, 0.5, &untiled, "ply");
    let mut samples_args = untiled.to_vec();
    samples_args.extend(["--vertex-heights", "samples"]);
    let samples = mesh_then_verify(&dem, 0.5, &samples_args, "ply");
    assert_eq!(raised["vertex_heights"], "raised");
    assert_eq!(samples["vertex_heights"], "samples");
    let count = |r: &serde_json::Value| r["triangles_after"].as_f64().unwrap();
    assert!(
        count(&raised) < 0.95 * count(&samples),
        "raised {} vs samples {}",
        count(&raised),
        count(&samples)
    );
    // The report says what came out: the paper's bounds keep vertices at their samples.
    let mut bounds_args = untiled.to_vec();
    bounds_args.extend(["--error-model", "bounds"]);
    let bounds = mesh_then_verify(&dem, 0.5, &bounds_args, "ply");
    assert_eq!(bounds["vertex_heights"], "samples");
    // Tiled, too: tiles agree on their shared edges (the engine checks the weld).
    let tiled = mesh_then_verify(&dem, 0.5, &["--tile-size", "128"], "ply");
    assert!(tiled["tiles"]["count"].as_u64().unwrap() > 4);
}

/// Whether an OBJ height field is not a whole number (a raised vertex over integer data).
fn off_integer_height(z: &str) -> bool {
    z.parse::<f64>().expect("OBJ height").fract() != 0.0
}

/// How many of an OBJ's vertices are off whole-number heights.
fn off_integer_vertices(obj: &str) -> usize {
    obj.lines()
        .filter(|l| l.starts_with("v "))
        .filter(|l| l.split(' ').nth(3).is_some_and(off_integer_height))
        .count()
}

#[test]
fn the_report_says_which_vertex_heights_came_out_with_contour_levels() {
    // Contour levels keep vertices at their samples; an interval with no level inside the
    // raster's range (350 to 2,583 here) shapes nothing, so vertices are
    // raised as without one. The report must say what the file holds, tiled or not.
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    for (interval, expected) in [("100", "samples"), ("100000", "raised")] {
        for tile_size in ["1024", "128"] {
            let d = Dir::new();
            let o = d.run(&[
                "mesh",
                &dem,
                "-o",
                "m.obj",
                "--max-error",
                "1",
                "--contour-interval",
                interval,
                "--tile-size",
                tile_size,
                "--report",
                "r.json",
                "-q",
            ]);
            assert!(o.status.success(), "{}", crate::util::stderr(&o));
            let report: serde_json::Value =
                serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
            let obj = std::fs::read_to_string(d.path("m.obj")).unwrap();
            let holds = if off_integer_vertices(&obj) > 0 {
                "raised"
            } else {
                "samples"
            };
            assert_eq!(holds, expected, "interval {interval}, tiles of {tile_size}");
            assert_eq!(report["vertex_heights"], expected, "interval {interval}");
        }
    }
}

#[test]
fn contour_reads_a_mesh_with_raised_heights_and_still_refuses_a_foreign_one() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let o = d.run(&["mesh", &dem, "-o", "m.obj", "--max-error", "1", "-q"]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    let obj = std::fs::read_to_string(d.path("m.obj")).unwrap();
    let off_sample = off_integer_vertices(&obj);
    assert!(
        off_sample > 100,
        "{off_sample} vertices off their integer samples"
    );
    let o = d.run(&[
        "contour",
        &dem,
        "--mesh",
        "m.obj",
        "-o",
        "c.geojson",
        "--interval",
        "100",
        "-q",
    ]);
    assert!(o.status.success(), "{}", crate::util::stderr(&o));
    // Moving one vertex by a unit is still refused: a border vertex (the first, not
    // raised) or an inner one (then raised by another amount than the rest).
    for (pick, name) in [(0, "border.obj"), (1, "inner.obj")] {
        let mut moved = String::new();
        let mut done = false;
        for line in obj.lines() {
            match line.strip_prefix("v ") {
                Some(rest)
                    if !done
                        && (pick == 0 || off_integer_height(rest.split(' ').nth(2).unwrap())) =>
                {
                    let f: Vec<f64> = rest.split(' ').map(|s| s.parse().unwrap()).collect();
                    moved.push_str(&format!("v {} {} {}\n", f[0], f[1], f[2] + 1.0));
                    done = true;
                }
                _ => {
                    moved.push_str(line);
                    moved.push('\n');
                }
            }
        }
        assert!(done);
        d.write(name, &moved);
        let o = d.run(&[
            "contour",
            &dem,
            "--mesh",
            name,
            "-o",
            "c2.geojson",
            "--interval",
            "100",
            "-q",
        ]);
        assert!(!o.status.success(), "{name}");
        assert!(
            crate::util::stderr(&o).contains(name),
            "{}",
            crate::util::stderr(&o)
        );
    }
}

#[test]
fn wgs84_geojson_rounded_by_another_tool_is_named_as_rounded() {
    // ogr2ogr rewrites RFC 7946 GeoJSON with 7 decimals (about 1 cm): too coarse for
    // verify to take 50 m pixels' vertices for their samples. The message says so, and
    // how to keep the digits; rounded to 12 decimals the file still verifies.
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let o = d.run(&["mesh", &dem, "-o", "m.geojson", "--max-error", "5", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.path("m.geojson")).unwrap();
    let rounded = |decimals: i32| -> String {
        let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
        let scale = 10f64.powi(decimals);
        for feature in json["features"].as_array_mut().unwrap() {
            for ring in feature["geometry"]["coordinates"].as_array_mut().unwrap() {
                for point in ring.as_array_mut().unwrap() {
                    for k in 0..2 {
                        let v = point[k].as_f64().unwrap();
                        point[k] = serde_json::json!((v * scale).round() / scale);
                    }
                }
            }
        }
        json.to_string()
    };
    d.write("r7.geojson", &rounded(7));
    d.write("r12.geojson", &rounded(12));
    let o = d.run(&["verify", &dem, "r7.geojson", "--max-error", "5"]);
    assert_eq!(o.status.code(), Some(2), "{}{}", stdout(&o), stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("r7.geojson: vertex")
            && err.contains("pixel off the sample centre")
            && err.contains("changed after it was written, and the mesh is measured as written")
            && err.contains("COORDINATE_PRECISION=15"),
        "{err}"
    );
    let o = d.run(&["verify", &dem, "r12.geojson", "--max-error", "5"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
}

/// The OBJ file's vertices.
fn obj_vertices(path: &std::path::Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|c| c.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn heights_converted_from_a_geoid_are_what_proj_gives() {
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let mesh = |out: &str, extra: &[&str]| {
        let mut args = vec!["mesh", &dem, "-o", out, "--max-error", "3", "-q"];
        args.extend_from_slice(extra);
        let o = d.run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    let geoid = ["--vertical-datum", "egm96", "--vertex-heights", "samples"];
    mesh(
        "whole.obj",
        &[&geoid[..], &["--tile-size", "1024", "--report", "r.json"]].concat(),
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path("r.json")).unwrap()).unwrap();
    assert_eq!(report["vertical_datum"], "egm96");

    // Each vertex sits on a sample: its height is that sample (read by gdallocationinfo)
    // plus EGM96's undulation at the sample's longitude, latitude (gdaltransform), both
    // independent of tinsmith.
    let vertices: Vec<[f64; 3]> = obj_vertices(&d.path("whole.obj"))
        .into_iter()
        .step_by(97)
        .collect();
    assert!(vertices.len() > 20);
    let positions: String = vertices
        .iter()
        .map(|v| format!("{:?} {:?}\n", v[0], v[1]))
        .collect();
    let mut child = std::process::Command::new("gdallocationinfo")
        .args(["-valonly", "-geoloc", &dem])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("gdallocationinfo runs");
    let mut stdin = child.stdin.take().unwrap();
    let feeder =
        std::thread::spawn(move || std::io::Write::write_all(&mut stdin, positions.as_bytes()));
    let out = child.wait_with_output().unwrap();
    feeder.join().unwrap().unwrap();
    let samples: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect();
    // gdaltransform reads and writes longitude first.
    let lon_lat = crate::util::gdaltransform("EPSG:3005", "EPSG:4326", &vertices);
    let lon_lat: Vec<[f64; 3]> = lon_lat.iter().map(|p| [p[0], p[1], 0.0]).collect();
    let n = crate::util::gdaltransform("EPSG:4326+5773", "EPSG:4979", &lon_lat);
    for ((v, h), n) in vertices.iter().zip(&samples).zip(&n) {
        assert!(n[2].abs() > 5.0, "an undulation of {}", n[2]);
        assert!(
            (v[2] - (h + n[2])).abs() < 1e-6,
            "vertex {v:?}: sample {h} + N {}",
            n[2]
        );
    }

    // verify measures the same converted heights; the band's own are tens of metres off.
    let check = |mesh: &str, datum: bool| {
        let mut args = vec!["verify", &dem, mesh, "--max-error", "3"];
        if datum {
            args.extend(["--vertical-datum", "egm96"]);
        }
        d.run(&args)
    };
    assert!(check("whole.obj", true).status.success());
    let against_own = check("whole.obj", false);
    assert!(!against_own.status.success() && stdout(&against_own).contains("exceeds"));
    // Tiled (the default tile size splits this raster), the same heights and bound.
    mesh("tiled.obj", &geoid);
    let v = check("tiled.obj", true);
    assert!(v.status.success(), "{}", stdout(&v));
    let p = d.run(&[
        "preview",
        &dem,
        "tiled.obj",
        "-o",
        "p.png",
        "--vertical-datum",
        "egm96",
        "--error",
    ]);
    assert!(p.status.success(), "{}", stderr(&p));
}

#[test]
fn a_geoid_datum_needs_a_placed_raster_and_its_grid() {
    let d = Dir::new();
    let png = fixture("mr_heart_256x256_u8_frame07.png");
    let o = d.run(&[
        "mesh",
        &png,
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--vertical-datum",
        "egm96",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("no CRS or no geotransform"),
        "{}",
        stderr(&o)
    );
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let missing = d.path("nowhere.gtx");
    let missing = missing.to_str().unwrap();
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--vertical-datum",
        missing,
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("nowhere.gtx"), "{}", stderr(&o));
    assert!(d.files().is_empty(), "{:?}", d.files());
}
