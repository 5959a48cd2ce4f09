//! The tiled engine from the command line. Small `--tile-size` values force many
//! tiles on the committed fixtures; the welded file is checked by `tinsmith verify` (which
//! reads the whole raster untiled), for cracks by edge-use counts computed here from the
//! file and the raster's cells, and for byte-identical output across thread counts.

use std::collections::HashMap;
use std::path::Path;

use crate::util::{assert_fails_naming, fixture, stderr, stdout, Dir};

/// `tinsmith mesh` with `args`, which must succeed; returns the `--report` JSON.
fn mesh(d: &Dir, args: &[&str]) -> serde_json::Value {
    let mut all = vec!["mesh", "--report", "r.json"];
    all.extend_from_slice(args);
    let o = d.run(&all);
    assert!(o.status.success(), "mesh {args:?} failed: {}", stderr(&o));
    serde_json::from_slice(&std::fs::read(d.path("r.json")).expect("report")).expect("json")
}

/// `tinsmith verify` on the written file at `e`, which must pass; returns its JSON.
fn verify(d: &Dir, input: &str, mesh: &str, e: &str, pixel: bool) -> serde_json::Value {
    let mut args = vec!["verify", input, mesh, "--max-error", e, "--json"];
    if pixel {
        args.push("--pixel-coords");
    }
    let o = d.run(&args);
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("verify --json");
    assert!(o.status.success(), "verify failed: {json:#}");
    assert_eq!(json["uncovered_samples"], 0);
    json
}

/// Every edge of the mesh (written with `--pixel-coords`) is used by at most two
/// triangles, and an edge used once lies on the outline of the raster's domain: along
/// cell sides, with no valid cell on the side away from its triangle.
pub(crate) fn assert_crack_free(input: &str, mesh: &Path) {
    let raster = tinsmith_raster::read_samples(Path::new(input), 1).expect("raster");
    let grid = &raster.samples;
    let (w, h) = (grid.width() as i64, grid.height() as i64);
    let valid_cell = |cx: i64, cy: i64| {
        cx >= 0
            && cy >= 0
            && cx + 1 < w
            && cy + 1 < h
            && [(cx, cy), (cx + 1, cy), (cx, cy + 1), (cx + 1, cy + 1)]
                .iter()
                .all(|&(x, y)| grid.get(x as u32, y as u32).is_some())
    };
    let file = tinsmith_formats::read_mesh(mesh).expect("mesh");
    let p: Vec<[i64; 2]> = file
        .vertices
        .iter()
        .map(|v| [v[0] as i64, v[1] as i64])
        .collect();
    let mut uses: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for t in &file.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            uses.entry((a.min(b), a.max(b)))
                .or_default()
                .push(t[(k + 2) % 3]);
        }
    }
    let mut outline = 0;
    for (&(a, b), thirds) in &uses {
        let (pa, pb) = (p[a as usize], p[b as usize]);
        assert!(
            thirds.len() <= 2,
            "edge {pa:?}-{pb:?} used {} times",
            thirds.len()
        );
        if thirds.len() == 2 {
            continue;
        }
        outline += 1;
        let pc = p[thirds[0] as usize];
        let cells: Vec<(i64, i64)> = if pa[1] == pb[1] {
            let cy = if pc[1] > pa[1] { pa[1] - 1 } else { pa[1] };
            (pa[0].min(pb[0])..pa[0].max(pb[0]))
                .map(|x| (x, cy))
                .collect()
        } else if pa[0] == pb[0] {
            let cx = if pc[0] > pa[0] { pa[0] - 1 } else { pa[0] };
            (pa[1].min(pb[1])..pa[1].max(pb[1]))
                .map(|y| (cx, y))
                .collect()
        } else {
            panic!("edge {pa:?}-{pb:?} used once but not along cell sides: a crack");
        };
        for (cx, cy) in cells {
            assert!(
                !valid_cell(cx, cy),
                "edge {pa:?}-{pb:?} used once beside valid cell ({cx}, {cy}): a crack"
            );
        }
    }
    assert!(outline > 0);
}

#[test]
fn welded_mesh_keeps_the_bound_and_has_no_cracks() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    // The level-aware DP, both kinds of edge flips and the extended holes' flips inside
    // tiles must leave the shared borders alone too.
    for (size, e, extra) in [
        ("64", "5", &[][..]),
        ("17", "2", &[]),
        ("108", "0.5", &[]),
        ("64", "5", &["--contour-interval", "20"]),
        ("17", "2", &["--contour-interval", "20"]),
        ("64", "1", &["--flip-rounds", "3"]),
        ("64", "1", &["--extend-rounds", "2"]),
        (
            "17",
            "2",
            &["--extend-rounds", "1", "--error-model", "bounds"],
        ),
    ] {
        let d = Dir::new();
        let mut args = vec![
            &dem[..],
            "-o",
            "t.ply",
            "--max-error",
            e,
            "--tile-size",
            size,
            "--pixel-coords",
            "-q",
        ];
        args.extend_from_slice(extra);
        let r = mesh(&d, &args);
        let v = verify(&d, &dem, "t.ply", e, true);
        assert_eq!(r["triangles_after"], v["triangles"]);
        assert_eq!(r["vertices_after"], v["vertices"]);
        assert_eq!(r["measured_max_error"], v["max_error"]);
        assert_eq!(r["tiles"]["size"], size.parse::<u64>().unwrap());
        assert!(r["tiles"]["count"].as_u64().unwrap() > 4);
        assert_crack_free(&dem, &d.path("t.ply"));
    }
}

#[test]
fn netcdf4_tiles_print_nothing_but_the_summary() {
    // HDF5 keeps "print error stacks" per thread and the netCDF library turns it off only
    // in the thread that opens first: every tile worker printed pages of HDF5-DIAG stacks
    // for attributes GDAL's driver merely probes, -q or not.
    let d = Dir::new();
    let o = std::process::Command::new("gdal_translate")
        .current_dir(d.path(""))
        .args(["-q", "-of", "netCDF", "-co", "FORMAT=NC4"])
        .args([&fixture("becmodel_dem_bc_albers_50m.tif"), "dem.nc"])
        .output()
        .expect("gdal_translate (Debian gdal-bin) must be on PATH");
    assert!(o.status.success(), "{}", stderr(&o));
    for args in [
        &[
            "mesh",
            "dem.nc",
            "-o",
            "t.ply",
            "--max-error",
            "3",
            "--tile-size",
            "128",
        ][..],
        &[
            "contour",
            "dem.nc",
            "-o",
            "c.fgb",
            "--interval",
            "50",
            "--max-error",
            "5",
            "--tile-size",
            "128",
        ],
        &["tiles", "dem.nc", "-o", "pyramid", "--max-zoom", "9"],
    ] {
        let args = [args, &["-q"]].concat();
        let o = d.run(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{args:?} printed on stderr");
    }
    verify(&d, "dem.nc", "t.ply", "3", false);
}

#[test]
fn raster_not_a_multiple_of_the_tile_size() {
    // 430 x 516: with 108 the last tile column is 2 samples wide; with 100 neither
    // dimension is a multiple.
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    for (size, columns, rows) in [("108", 5, 5), ("100", 5, 6)] {
        let d = Dir::new();
        let r = mesh(
            &d,
            &[&dem, "-o", "t.obj", "--max-error", "3", "--tile-size", size],
        );
        assert_eq!(r["tiles"]["columns"], columns);
        assert_eq!(r["tiles"]["rows"], rows);
        verify(&d, &dem, "t.obj", "3", false);
    }
}

#[test]
fn nodata_across_tile_edges() {
    // tin-terrain's Float32 tile (-FLT_MAX nodata) and the Hugo site (-9999 nodata, an
    // irregular outline): small tiles put nodata on many tile edges.
    for (name, size, e) in [
        ("tintn_valid_raster_3857.tif", "9", "0.5"),
        ("landlab_hugo_site.asc", "7", "1"),
        ("landlab_west_bijou_gully.asc", "12", "0.25"),
    ] {
        let dem = fixture(name);
        let d = Dir::new();
        mesh(
            &d,
            &[
                &dem,
                "-o",
                "t.ply",
                "--max-error",
                e,
                "--tile-size",
                size,
                "--pixel-coords",
            ],
        );
        verify(&d, &dem, "t.ply", e, true);
        assert_crack_free(&dem, &d.path("t.ply"));
    }
}

#[test]
fn tiles_of_two_by_two_samples() {
    let dem = fixture("landlab_hugo_site.asc");
    let d = Dir::new();
    let r = mesh(
        &d,
        &[
            &dem,
            "-o",
            "t.ply",
            "--max-error",
            "100",
            "--tile-size",
            "2",
            "--pixel-coords",
        ],
    );
    assert_eq!(r["tiles"]["count"], 75 * 54);
    // One cell per tile: nothing can be removed.
    assert_eq!(r["triangles_after"], r["triangles_before"]);
    verify(&d, &dem, "t.ply", "100", true);
    assert_crack_free(&dem, &d.path("t.ply"));
}

#[test]
fn same_bytes_for_one_and_two_threads_and_run_to_run() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    for ext in ["ply", "obj"] {
        let mut files = Vec::new();
        // 0 is one per core, as in `tiles` (it used to be refused by `mesh` and `contour`).
        for (i, threads) in ["1", "2", "2", "1", "0"].iter().enumerate() {
            let out = format!("t{i}.{ext}");
            mesh(
                &d,
                &[
                    &dem,
                    "-o",
                    &out,
                    "--max-error",
                    "2",
                    "--tile-size",
                    "33",
                    "--threads",
                    threads,
                ],
            );
            files.push(std::fs::read(d.path(&out)).expect("output"));
        }
        assert!(
            files.windows(2).all(|w| w[0] == w[1]),
            "{ext} output differs"
        );
    }
}

#[test]
fn no_more_workers_start_than_there_are_cores_or_tiles_and_at_most_1024() {
    // --threads 100000 started ~15,700 threads before one failed to start, then hung;
    // --threads 1000 on four tiles took 5 s; --threads 1024 on 1,015 tiles and 2 cores
    // took 17 s and 1.19 GB instead of 0.31 s and 60 MB. Workers beyond the cores the
    // process may use, or the tiles, are not started.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    for (tile_size, threads) in [("300", "64"), ("16", "1024")] {
        let args = [
            &dem,
            "-o",
            "m.ply",
            "--max-error",
            "5",
            "--tile-size",
            tile_size,
        ];
        let r = mesh(&d, &[&args[..], &["--threads", threads]].concat());
        let tiles = r["tiles"]["count"].as_u64().expect("tile count") as usize;
        assert_eq!(tiles, if tile_size == "300" { 4 } else { 1015 });
        assert_eq!(
            r["tiles"]["threads"],
            cores.min(tiles),
            "--threads {threads}"
        );
    }
    for command in [
        vec![
            "mesh",
            &dem,
            "-o",
            "n.ply",
            "--max-error",
            "5",
            "--threads",
            "100000",
        ],
        vec![
            "contour",
            &dem,
            "-o",
            "n.fgb",
            "--levels",
            "500",
            "--threads",
            "1025",
        ],
        vec!["tiles", &dem, "-o", "n", "--threads", "100000"],
    ] {
        let o = d.run(&command);
        assert_eq!(o.status.code(), Some(2), "{command:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("1024"), "{}", stderr(&o));
    }
    assert_eq!(d.files(), vec!["m.ply", "r.json"]);
}

#[test]
fn per_tile_directory_has_one_file_per_tile() {
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    let r = mesh(
        &d,
        &[
            &dem,
            "--per-tile",
            "tiles",
            "--max-error",
            "0.5",
            "--tile-size",
            "40",
            "--tile-format",
            "obj",
        ],
    );
    // 100 x 80 samples, 39 cells per tile: 3 x 3 tiles.
    assert_eq!(r["tiles"]["count"], 9);
    assert_eq!(r["tiles"]["welded"], false);
    let mut names: Vec<String> = std::fs::read_dir(d.path("tiles"))
        .expect("tiles dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".obj")) // each tile also gets its .prj sidecar
        .collect();
    names.sort();
    assert_eq!(names.len(), 9);
    assert_eq!(names[0], "tile_r0_c0.obj");
    assert_eq!(names[8], "tile_r2_c2.obj");
    let (mut triangles, mut vertices) = (0, 0);
    for n in &names {
        let m = tinsmith_formats::read_mesh(&d.path("tiles").join(n)).expect("tile mesh");
        assert!(m.crs_wkt.is_some());
        triangles += m.triangles.len() as u64;
        vertices += m.vertices.len() as u64;
    }
    assert_eq!(triangles, r["triangles_after"].as_u64().unwrap());
    // Welded, the same tiles have the same triangles and fewer vertices: each shared edge
    // vertex once.
    let w = mesh(
        &d,
        &[
            &dem,
            "-o",
            "w.ply",
            "--max-error",
            "0.5",
            "--tile-size",
            "40",
        ],
    );
    assert_eq!(w["triangles_after"], r["triangles_after"]);
    assert_eq!(w["vertices_after"], r["vertices_after"]);
    assert!(w["vertices_after"].as_u64().unwrap() < vertices);
}

#[test]
fn per_tile_refuses_a_non_empty_directory_and_leaves_nothing() {
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    std::fs::create_dir(d.path("tiles")).expect("mkdir");
    d.write("tiles/keep.txt", "mine");
    let o = d.run(&[
        "mesh",
        &dem,
        "--per-tile",
        "tiles",
        "--max-error",
        "1",
        "--tile-size",
        "40",
    ]);
    assert_fails_naming(&o, &["tiles", "not an empty directory"]);
    assert_eq!(d.files(), vec!["tiles"]);
}

#[test]
fn per_tile_names_what_is_in_the_way() {
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    d.write("afile", "x");
    std::fs::create_dir(d.path("empty")).unwrap();
    std::os::unix::fs::symlink("empty", d.path("link")).unwrap();
    for (dir, names) in [
        // It said "parent directory afile does not exist".
        ("afile/sub", &["afile/sub", "afile is a file"][..]),
        // It said "exists and is not a directory".
        ("link", &["link", "symbolic link"][..]),
    ] {
        let o = d.run(&["mesh", &dem, "--per-tile", dir, "--max-error", "1"]);
        assert_fails_naming(&o, names);
    }
    assert_eq!(d.files(), vec!["afile", "empty", "link"]);
}

#[test]
fn per_tile_refuses_options_of_formats_it_does_not_write() {
    // --per-tile writes PLY or OBJ (--tile-format); these were silently ignored.
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    for (extra, option) in [
        (&["--format", "glb"][..], "--format"),
        (&["--base", "-100"][..], "--base"),
        (&["--normals"][..], "--normals"),
        (&["--geojson-source-crs"][..], "--geojson-source-crs"),
    ] {
        let mut args = vec!["mesh", &dem, "--per-tile", "tiles", "--max-error", "1"];
        args.extend_from_slice(extra);
        let o = d.run(&args);
        assert_fails_naming(&o, &[option, "--per-tile", "OBJ files (--tile-format)"]);
        assert!(d.files().is_empty(), "{option}: left {:?}", d.files());
    }
}

#[test]
fn count_targets_run_untiled_whatever_the_tile_size() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let r = mesh(
        &d,
        &[
            &dem,
            "-o",
            "t.ply",
            "--max-triangles",
            "1000",
            "--tile-size",
            "64",
            "-q",
        ],
    );
    assert!(
        r.get("tiles").is_none(),
        "a count target needs the whole raster"
    );
    assert!(r["triangles_after"].as_u64().unwrap() <= 1000);
    let v = verify(&d, &dem, "t.ply", "1e9", false);
    assert_eq!(r["measured_max_error"], v["max_error"]);

    let o = d.run(&[
        "mesh",
        &dem,
        "--per-tile",
        "tiles",
        "--max-triangles",
        "1000",
        "--tile-size",
        "64",
    ]);
    assert_fails_naming(&o, &["becmodel_dem_bc_albers_50m.tif", "--per-tile"]);
    assert_eq!(d.files(), vec!["r.json", "t.ply"]);
}

#[test]
fn every_format_is_written_from_tiles() {
    // PLY and OBJ stream tile by tile; the others are welded in memory and written at the
    // end. Every file keeps the bound (float32 formats too) and holds the same mesh.
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let e = "2";
    let base = mesh(
        &d,
        &[
            &dem,
            "-o",
            "t.ply",
            "--max-error",
            e,
            "--tile-size",
            "64",
            "-q",
        ],
    );
    for name in ["t.fgb", "t.geojson", "t.stl", "t.glb", "t.xml", "t.obj"] {
        let r = mesh(
            &d,
            &[
                &dem,
                "-o",
                name,
                "--max-error",
                e,
                "--tile-size",
                "64",
                "-q",
            ],
        );
        assert!(r["tiles"]["count"].as_u64().unwrap() > 4, "{name}: tiled");
        let v = verify(&d, &dem, name, e, false);
        assert!(v["max_error"].as_f64().unwrap() <= 2.0, "{name}: {v:#}");
        assert_eq!(v["triangles"], r["triangles_after"], "{name}");
        // STL stores unshared corners; the others share vertices as the run reports them.
        if name != "t.stl" {
            assert_eq!(v["vertices"], r["vertices_after"], "{name}");
        }
        if !name.ends_with(".stl") && !name.ends_with(".glb") {
            assert_eq!(r["triangles_after"], base["triangles_after"], "{name}");
        }
        // OBJ, STL and glTF carry the CRS in a .prj sidecar, streamed (OBJ) or not.
        if [".obj", ".stl", ".glb"].iter().any(|e| name.ends_with(e)) {
            let prj = d.path(name).with_extension("prj");
            let wkt = std::fs::read_to_string(&prj).unwrap_or_default();
            assert!(
                wkt.contains("PROJCS") || wkt.contains("PROJCRS"),
                "{name}: {wkt:?}"
            );
            std::fs::remove_file(prj).unwrap();
        }
    }
}

#[test]
fn all_nodata_and_no_valid_cell_fail_cleanly_in_tiled_mode() {
    let d = Dir::new();
    d.write(
        "empty.asc",
        "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n-9999 -9999 -9999\n-9999 -9999 -9999\n",
    );
    let o = d.run(&[
        "mesh",
        "empty.asc",
        "-o",
        "out.ply",
        "--max-error",
        "1",
        "--tile-size",
        "2",
    ]);
    assert_fails_naming(&o, &["empty.asc", "nodata"]);
    d.write(
        "row.asc",
        "ncols 4\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 2 3 4\n-9999 -9999 -9999 -9999\n",
    );
    let o = d.run(&[
        "mesh",
        "row.asc",
        "-o",
        "out.ply",
        "--max-error",
        "1",
        "--tile-size",
        "2",
    ]);
    assert_fails_naming(&o, &["row.asc", "2x2"]);
    assert_eq!(d.files(), vec!["empty.asc", "row.asc"]);
}

#[test]
fn small_rasters_stay_untiled_and_unchanged() {
    // Below the tile size the untiled engine runs: same bytes as before tiling existed
    // (the report has no tile fields).
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    let r = mesh(&d, &[&dem, "-o", "a.ply", "--max-error", "0.5"]);
    assert!(r.get("tiles").is_none());
    let r = mesh(
        &d,
        &[
            &dem,
            "-o",
            "b.ply",
            "--max-error",
            "0.5",
            "--tile-size",
            "100",
            "--threads",
            "1",
        ],
    );
    assert!(r.get("tiles").is_none());
    assert_eq!(
        std::fs::read(d.path("a.ply")).unwrap(),
        std::fs::read(d.path("b.ply")).unwrap()
    );
}

#[test]
fn quiet_and_piped_runs_print_no_progress() {
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "t.ply",
        "--max-error",
        "5",
        "--tile-size",
        "64",
        "-q",
    ]);
    assert!(o.status.success());
    assert_eq!(stderr(&o), "");
    // stderr is a pipe here: no progress bar, only the summary line.
    let o = d.run(&[
        "mesh",
        &dem,
        "-o",
        "t.ply",
        "--max-error",
        "5",
        "--tile-size",
        "64",
    ]);
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err:?}");
    assert!(err.contains("in 63 tiles of 64"), "{err}");
}
