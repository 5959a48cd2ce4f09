//! `tinsmith preview`: the PNG read back by an independent decoder (Pillow,
//! `tests/oracles/png_pixels.py`), its edges where the mesh has them, and the refusals.
//! `#[ignore]`d so that `cargo test` passes without the oracles; `make test` runs them.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::util::{assert_fails_naming, fixture, stderr, Dir};

/// Pillow's view of `png`, with the RGB of each pixel of `points`.
fn pillow(png: &Path, points: &[(u32, u32)]) -> Value {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let python = repo.join(".venv/bin/python3");
    assert!(
        python.exists(),
        "oracle missing: {}; run `make deps`",
        python.display()
    );
    let out = Command::new(&python)
        .arg(repo.join("tests/oracles/png_pixels.py"))
        .arg(png)
        .args(points.iter().map(|(x, y)| format!("{x},{y}")))
        .output()
        .expect("python runs");
    assert!(out.status.success(), "Pillow: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("JSON")
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_preview_shows_the_tins_edges_where_the_mesh_has_them() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let run = |args: &[&str]| {
        let o = dir.run(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    run(&[
        "mesh",
        &dem,
        "--max-error",
        "20",
        "--pixel-coords",
        "-o",
        "m.ply",
        "-q",
    ]);
    let common = ["--pixel-coords", "--size", "700"];
    let with = |out: &str, layers: &[&str]| {
        let mut args = vec!["preview", dem.as_str(), "m.ply", "-o", out];
        args.extend(common);
        args.extend(layers);
        run(&args);
    };
    with("wired.png", &["--hillshade", "--wireframe"]);
    with("plain.png", &["--hillshade"]);
    with("again.png", &["--hillshade", "--wireframe"]);
    let bytes = std::fs::read(dir.path("wired.png")).unwrap();
    assert_eq!(
        bytes,
        std::fs::read(dir.path("again.png")).unwrap(),
        "same bytes"
    );

    // The mesh's vertices are (column, row, height): the picture's pixel of sample
    // (x, y) is ((x + 0.5) s, (y + 0.5) s), s = 700 / the raster's longer side.
    let mesh = tinsmith_formats::read_mesh(&dir.path("m.ply")).unwrap();
    let columns = mesh.vertices.iter().map(|v| v[0]).fold(0.0, f64::max) + 1.0;
    let rows = mesh.vertices.iter().map(|v| v[1]).fold(0.0, f64::max) + 1.0;
    let s = 700.0 / columns.max(rows);
    let pixel = |x: f64, y: f64| (((x + 0.5) * s) as u32, ((y + 0.5) * s) as u32);
    // Midpoints of long edges, and centroids of triangles wide enough that no edge comes
    // within 3 pixels of them.
    let mut on_edges = Vec::new();
    let mut inside = Vec::new();
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.vertices[i as usize]);
        let (a, b) = (p[0], p[1]);
        if on_edges.len() < 40 && (b[0] - a[0]).hypot(b[1] - a[1]) * s > 8.0 {
            on_edges.push(pixel((a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0));
        }
        let c = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ];
        let distance = |u: [f64; 3], v: [f64; 3]| {
            let (dx, dy) = (v[0] - u[0], v[1] - u[1]);
            ((c[0] - u[0]) * dy - (c[1] - u[1]) * dx).abs() / dx.hypot(dy)
        };
        let nearest = distance(p[0], p[1])
            .min(distance(p[1], p[2]))
            .min(distance(p[2], p[0]));
        if inside.len() < 40 && nearest * s > 3.0 {
            inside.push(pixel(c[0], c[1]));
        }
    }
    assert!(on_edges.len() >= 20 && inside.len() >= 20);
    let points: Vec<(u32, u32)> = on_edges.iter().chain(&inside).copied().collect();
    let wired = pillow(&dir.path("wired.png"), &points);
    let plain = pillow(&dir.path("plain.png"), &points);
    assert_eq!(wired["mode"], "RGB");
    assert_eq!(
        wired["width"]
            .as_u64()
            .unwrap()
            .max(wired["height"].as_u64().unwrap()),
        700
    );
    let n = on_edges.len();
    for (k, point) in points.iter().enumerate() {
        let (w, p) = (&wired["pixels"][k], &plain["pixels"][k]);
        if k < n {
            assert_ne!(w, p, "no edge drawn at {point:?}");
        } else {
            assert_eq!(w, p, "an edge drawn inside a triangle at {point:?}");
        }
    }
    let text = &wired["text"];
    assert_eq!(text["Source"], dem.as_str());
    let counts = format!(
        "{} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    assert_eq!(text["Counts"], counts.as_str());
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn the_error_map_has_its_legend_and_its_bound() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = dir.run(&["mesh", &dem, "--max-error", "10", "-o", "m.ply", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = dir.run(&[
        "preview",
        &dem,
        "m.ply",
        "-o",
        "e.png",
        "--error",
        "--max-error",
        "10",
        "--size",
        "400",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let seen = pillow(&dir.path("e.png"), &[(5, 394)]);
    assert_eq!(seen["text"]["Error scale"], "10");
    // No hillshade: the map's colours are the error's alone; the legend's box is white-ish.
    assert!(seen["pixels"][0]
        .as_array()
        .unwrap()
        .iter()
        .all(|v| v.as_u64().unwrap() > 180));
}

#[test]
fn bad_previews_are_refused_and_leave_no_file() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = dir.run(&["mesh", &dem, "--max-error", "20", "-o", "m.ply", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = dir.files();
    let o = dir.run(&["preview", &dem, "m.ply", "-o", "p.jpg"]);
    assert_fails_naming(&o, &["p.jpg", ".png"]);
    let o = dir.run(&["preview", &dem, "m.ply", "-o", "p.png", "--size", "8"]);
    assert_fails_naming(&o, &["--size 8"]);
    let o = dir.run(&["preview", &dem, "m.ply", "-o", "missing/p.png"]);
    assert_fails_naming(&o, &["missing"]);
    // A mesh of another raster.
    let other = fixture("etopo5_2deg_i16.tif");
    let o = dir.run(&["preview", &other, "m.ply", "-o", "p.png"]);
    assert_fails_naming(&o, &["m.ply"]);
    assert_eq!(dir.files(), before, "no file left");
}

#[test]
fn the_hillshade_is_gdaldems() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let out = Command::new("gdaldem")
        .args(["hillshade", "-q", &dem])
        .arg(dir.path("gdal.tif"))
        .output()
        .expect("gdaldem runs (gdal-bin)");
    assert!(out.status.success(), "gdaldem: {}", stderr(&out));
    let raster = tinsmith_raster::read_samples(Path::new(&dem), 1).unwrap();
    let gt = raster.info.geo_transform.unwrap();
    let (w, h) = (
        raster.samples.width() as usize,
        raster.samples.height() as usize,
    );
    let ours = tinsmith_preview::hillshade(raster.samples.values(), w, h, [gt[1], gt[5]]);
    let gdal = tinsmith_raster::read_samples(&dir.path("gdal.tif"), 1).unwrap();
    let theirs = gdal.samples.values();
    let mut compared = 0;
    for j in 1..h - 1 {
        for i in 1..w - 1 {
            let k = j * w + i;
            if theirs[k].is_finite() && ours[k].is_finite() {
                let d = (f64::from(ours[k]) - theirs[k]).abs();
                assert!(
                    d <= 1.0,
                    "sample {i}, {j}: ours {} gdaldem {}",
                    ours[k],
                    theirs[k]
                );
                compared += 1;
            }
        }
    }
    assert!(compared > w * h / 2);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn without_a_mesh_the_raster_is_decimated_first_as_mesh_decimates_it() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = dir.run(&["mesh", &dem, "--max-error", "20", "-o", "m.ply", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = dir.run(&[
        "preview",
        &dem,
        "-o",
        "d.png",
        "--max-error",
        "20",
        "--size",
        "300",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mesh = tinsmith_formats::read_mesh(&dir.path("m.ply")).unwrap();
    let seen = pillow(&dir.path("d.png"), &[]);
    let counts = format!(
        "{} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    assert_eq!(seen["text"]["Counts"], counts.as_str());
    assert_eq!(seen["text"]["Mesh"], "decimated by tinsmith within 20");
    // No temporary mesh left beside the picture.
    assert_eq!(dir.files(), ["d.png", "m.ply"]);
    let o = dir.run(&["preview", &dem, "-o", "e.png"]);
    assert_fails_naming(&o, &["MESH", "--max-error"]);
}

#[test]
fn mesh_preview_is_the_picture_preview_draws_of_the_written_mesh() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    // Tiled (the default tiles are smaller than the raster) and untiled.
    for (name, tiles) in [("tiled", "256"), ("whole", "4096")] {
        let (ply, png, again) = (
            format!("{name}.ply"),
            format!("{name}.png"),
            format!("{name}-again.png"),
        );
        let o = dir.run(&[
            "mesh",
            &dem,
            "--max-error",
            "20",
            "-o",
            &ply,
            "--preview",
            &png,
            "--tile-size",
            tiles,
            "-q",
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let o = dir.run(&["preview", &dem, &ply, "-o", &again]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let (a, b) = (
            std::fs::read(dir.path(&png)).unwrap(),
            std::fs::read(dir.path(&again)).unwrap(),
        );
        assert!(
            a.starts_with(b"\x89PNG") && a == b,
            "{name}: not the same picture"
        );
    }
    // A bad picture name is refused before anything is written.
    let before = dir.files();
    let o = dir.run(&[
        "mesh",
        &dem,
        "--max-error",
        "20",
        "-o",
        "x.ply",
        "--preview",
        "x.jpg",
    ]);
    assert_fails_naming(&o, &["x.jpg", ".png"]);
    assert_eq!(dir.files(), before);
}

/// Runs `tinsmith args...` in `dir` as if every raster were larger than a preview reads
/// whole: only the drawn samples are read.
fn run_drawn_samples_only(dir: &Dir, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(args)
        .env("TINSMITH_TEST_WHOLE_READ_SAMPLES", "0")
        .current_dir(dir.path("."))
        .output()
        .expect("run tinsmith")
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_raster_too_large_to_read_whole_gives_the_same_picture_from_its_drawn_samples() {
    let dir = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = dir.run(&["mesh", &dem, "--max-error", "5", "-o", "m.ply", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Smaller than the raster (a sparse lattice), and larger (every sample).
    for (size, layers) in [
        ("150", &["--hillshade", "--wireframe", "--error"][..]),
        ("333", &["--error"][..]),
        ("2000", &["--hillshade", "--wireframe"][..]),
    ] {
        let mut args = vec!["preview", dem.as_str(), "m.ply", "--size", size];
        args.extend(layers);
        let whole = dir.run(&[&args[..], &["-o", "whole.png"]].concat());
        assert!(whole.status.success(), "{}", stderr(&whole));
        assert!(
            !stderr(&whole).contains("not verified"),
            "{}",
            stderr(&whole)
        );
        let drawn = run_drawn_samples_only(&dir, &[&args[..], &["-o", "drawn.png"]].concat());
        assert!(drawn.status.success(), "{}", stderr(&drawn));
        assert!(
            stderr(&drawn).contains("at the drawn samples")
                && stderr(&drawn).contains("not verified at every sample"),
            "{}",
            stderr(&drawn)
        );
        let (a, b) = (
            std::fs::read(dir.path("whole.png")).unwrap(),
            std::fs::read(dir.path("drawn.png")).unwrap(),
        );
        assert!(a == b, "--size {size} {layers:?}: not the same picture");
    }
    // The error at the drawn samples is within the mesh's bound.
    let seen = pillow(&dir.path("drawn.png"), &[]);
    let value: f64 = seen["text"]["Max error at drawn samples"]
        .as_str()
        .and_then(|v| v.parse().ok())
        .expect("a number");
    assert!(value > 0.0 && value <= 5.0, "{value}");
    // A mesh of another raster is still refused by name, and nothing is written.
    let before = dir.files();
    let other = fixture("etopo5_2deg_i16.tif");
    let o = run_drawn_samples_only(&dir, &["preview", &other, "m.ply", "-o", "p.png"]);
    assert_fails_naming(&o, &["m.ply"]);
    assert_eq!(dir.files(), before, "no file left");
}
