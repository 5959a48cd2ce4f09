//! `tinsmith contour` on real rasters: GDAL's `ogrinfo` reads the GeoJSON and FlatGeobuf
//! output with the right feature count and CRS; GeoJSON is WGS84 unless
//! `--geojson-source-crs`, as GDAL transforms it; a mesh file gives the same lines as
//! decimating in place; bad input fails cleanly.

use std::process::Command;

use crate::util::{assert_fails_naming, fixture, gdaltransform, run_under_ulimit, stderr, Dir};

/// `ogrinfo -so -al FILE` (summary of every layer). gdal-bin is installed by `make deps`.
fn ogrinfo(path: &std::path::Path) -> String {
    let o = Command::new("ogrinfo")
        .args(["-so", "-al"])
        .arg(path)
        .output()
        .expect("ogrinfo (Debian gdal-bin, installed by `make deps`) must be on PATH");
    assert!(o.status.success(), "ogrinfo failed: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn run_ok(d: &Dir, args: &[&str]) {
    let o = d.run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

/// The features of a GeoJSON file we wrote, as (elev, points).
fn features(path: &std::path::Path) -> Vec<(f64, Vec<[f64; 2]>)> {
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    v["features"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            assert_eq!(f["properties"]["id"], i);
            assert_eq!(f["geometry"]["type"], "LineString");
            let pts: Vec<[f64; 2]> = serde_json::from_value(f["geometry"]["coordinates"].clone())
                .expect("2D coordinates");
            assert!(pts.len() >= 2);
            (f["properties"]["elev"].as_f64().unwrap(), pts)
        })
        .collect()
}

/// Runs `contour` to GeoJSON (default: WGS84), GeoJSON with `--geojson-source-crs` and
/// FlatGeobuf, and checks what `ogrinfo` reads: the same feature count, line strings, the
/// `id` and `elev` attributes, and the CRS (EPSG:4326 for the default GeoJSON, the
/// raster's for the others). Returns the number of lines.
fn check_read_by_gdal(input: &str, epsg: &str, args: &[&str]) -> usize {
    let d = Dir::new();
    let outputs = [
        ("c.geojson", "4326", &[][..]),
        ("src.geojson", epsg, &["--geojson-source-crs"][..]),
        ("c.fgb", epsg, &[][..]),
    ];
    for (file, _, extra) in outputs {
        let mut a = vec!["contour", input, "-o", file];
        a.extend_from_slice(args);
        a.extend_from_slice(extra);
        run_ok(&d, &a);
    }
    let n = features(&d.path("c.geojson")).len();
    assert!(n > 0);
    for (file, epsg, _) in outputs {
        let info = ogrinfo(&d.path(file));
        assert!(
            info.contains(&format!("Feature Count: {n}\n")),
            "{file}: {info}"
        );
        assert!(info.contains("Geometry: Line String"), "{file}: {info}");
        assert!(info.contains("elev: Real"), "{file}: {info}");
        assert!(info.contains("id: Integer"), "{file}: {info}");
        assert!(
            info.contains(&format!("ID[\"EPSG\",{epsg}]]\nData axis")),
            "{file} should be EPSG:{epsg}: {info}"
        );
    }
    assert_eq!(
        d.files(),
        vec!["c.fgb", "c.geojson", "src.geojson"],
        "no temporary file left"
    );
    n
}

#[test]
fn geojson_is_wgs84_by_default_like_mesh() {
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let base = ["contour", &input, "--interval", "500", "--max-error", "10"];
    let mut a = base.to_vec();
    a.extend_from_slice(&["-o", "wgs84.geojson"]);
    run_ok(&d, &a);
    let mut b = base.to_vec();
    b.extend_from_slice(&["-o", "src.geojson", "--geojson-source-crs"]);
    run_ok(&d, &b);
    let json = |name: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.path(name)).unwrap()).unwrap()
    };
    // RFC 7946: no crs member; the source CRS file names it, with a note.
    assert!(json("wgs84.geojson").get("crs").is_none());
    let src = json("src.geojson");
    assert_eq!(
        src["crs"]["properties"]["name"],
        "urn:ogc:def:crs:EPSG::3005"
    );
    assert!(src["tinsmith_note"].as_str().is_some());
    // The same lines, point for point, as GDAL transforms them.
    let (wgs84, src) = (
        features(&d.path("wgs84.geojson")),
        features(&d.path("src.geojson")),
    );
    assert_eq!(wgs84.len(), src.len());
    let src_points: Vec<[f64; 3]> = src
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| [q[0], q[1], 0.0]))
        .collect();
    let expected = gdaltransform("EPSG:3005", "EPSG:4326", &src_points);
    let got: Vec<[f64; 2]> = wgs84.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    assert_eq!(got.len(), expected.len());
    for (g, e) in got.iter().zip(&expected) {
        assert!(
            (g[0] - e[0]).abs() < 1e-9 && (g[1] - e[1]).abs() < 1e-9,
            "{g:?} vs {e:?}"
        );
    }
    for ((ew, _), (es, _)) in wgs84.iter().zip(&src) {
        assert_eq!(ew, es);
    }
    // Longitude, latitude: the DEM is in southern British Columbia.
    assert!(got
        .iter()
        .all(|p| (-121.0..-119.0).contains(&p[0]) && (48.5..49.5).contains(&p[1])));
}

#[test]
fn ogrinfo_reads_geojson_and_fgb_with_count_and_crs() {
    check_read_by_gdal(
        &fixture("tintn_valid_raster_3857.tif"),
        "3857",
        &["--interval", "2", "--max-error", "0.5"],
    );
    check_read_by_gdal(
        &fixture("becmodel_dem_bc_albers_50m.tif"),
        "3005",
        &["--interval", "100", "--offset", "50", "--max-error", "10"],
    );
    // The full grid (the default) and explicit levels, negative ones too.
    check_read_by_gdal(
        &fixture("becmodel_dem_bc_albers_50m.tif"),
        "3005",
        &["--levels", "-5,1000,1500,2000"],
    );
}

#[test]
fn lines_are_closed_or_end_on_the_domain_edge_in_world_coordinates() {
    // hugo_site: half nodata, no CRS, origin (0, 0), 10 m cells, 76 x 55.
    let d = Dir::new();
    let input = fixture("landlab_hugo_site.asc");
    run_ok(
        &d,
        &[
            "contour",
            &input,
            "-o",
            "c.json",
            "--interval",
            "2",
            "--max-error",
            "0.5",
        ],
    );
    let f = features(&d.path("c.json"));
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("c.json")).unwrap()).unwrap();
    assert!(v["crs"].is_null(), "no CRS to record: \"crs\": null");
    assert!(f.iter().any(|(_, p)| p.first() == p.last()));
    for (elev, pts) in &f {
        assert_eq!(elev % 2.0, 0.0);
        // Sample centres: x in 5..755, y in 5..545.
        for p in pts {
            assert!(
                (5.0..=755.0).contains(&p[0]) && (5.0..=545.0).contains(&p[1]),
                "{p:?}"
            );
        }
    }
    // Sorted by level.
    assert!(f.windows(2).all(|w| w[0].0 <= w[1].0));
    // Same bytes every run.
    run_ok(
        &d,
        &[
            "contour",
            &input,
            "-o",
            "again.json",
            "--interval",
            "2",
            "--max-error",
            "0.5",
        ],
    );
    assert_eq!(
        std::fs::read(d.path("c.json")).unwrap(),
        std::fs::read(d.path("again.json")).unwrap()
    );
}

/// Lines in an order independent of vertex numbering: rings start at their smallest
/// point, lines are sorted. (Open lines keep their direction: high ground on the left.)
fn canonical(mut lines: Vec<(f64, Vec<[f64; 2]>)>) -> Vec<(f64, Vec<[f64; 2]>)> {
    let key = |p: &[f64; 2]| (p[0].to_bits(), p[1].to_bits());
    for (_, points) in &mut lines {
        if points.first() == points.last() {
            points.pop();
            let start = (0..points.len())
                .min_by(|&i, &j| points[i].partial_cmp(&points[j]).unwrap())
                .unwrap();
            points.rotate_left(start);
            points.push(points[0]);
        }
    }
    lines.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then_with(|| a.1.iter().map(key).cmp(b.1.iter().map(key)))
    });
    lines
}

#[test]
fn mesh_file_gives_the_same_lines_as_decimating() {
    let input = fixture("tintn_valid_raster_3857.tif");
    // A GeoJSON mesh is in WGS84 and is transformed back, as `verify` does.
    for (mesh, extra) in [
        ("m.ply", &[][..]),
        ("m.geojson", &[][..]),
        ("m.ply", &["--pixel-coords"][..]),
    ] {
        let d = Dir::new();
        // The TIN `contour` decimates is shaped for its levels; `mesh` shapes it alike.
        let mut m = vec![
            "mesh",
            &input,
            "-o",
            mesh,
            "--max-error",
            "0.5",
            "--contour-interval",
            "1",
        ];
        m.extend_from_slice(extra);
        run_ok(&d, &m);
        let mut a = vec!["contour", &input, "-o", "a.geojson", "--interval", "1"];
        a.extend_from_slice(extra);
        let mut b = a.clone();
        a.extend_from_slice(&["--mesh", mesh]);
        b[3] = "b.geojson";
        b.extend_from_slice(&["--max-error", "0.5"]);
        run_ok(&d, &a);
        run_ok(&d, &b);
        let (fa, fb) = (
            features(&d.path("a.geojson")),
            features(&d.path("b.geojson")),
        );
        assert!(!fa.is_empty());
        if mesh.ends_with(".ply") {
            assert_eq!(fa, fb, "{mesh} {extra:?}");
        } else {
            // GeoJSON has no shared vertices: the reader welds them in its own order, and
            // the line order and ring starts follow vertex numbers.
            assert_eq!(canonical(fa), canonical(fb), "{mesh} {extra:?}");
        }
    }
}

#[test]
fn tiled_decimation_contours_the_same_tin_mesh_writes() {
    // Above --tile-size, contour decimates through the tiled engine: the lines are those of
    // the welded TIN `tinsmith mesh --tile-size` writes, for 1 or 2 threads.
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let tiles = ["--tile-size", "128", "--max-error", "5"];
    let mut m = vec![
        "mesh",
        &input,
        "-o",
        "m.ply",
        "-q",
        "--contour-interval",
        "50",
    ];
    m.extend_from_slice(&tiles);
    run_ok(&d, &m);
    run_ok(
        &d,
        &[
            "contour",
            &input,
            "-o",
            "a.geojson",
            "--interval",
            "50",
            "--mesh",
            "m.ply",
            "-q",
        ],
    );
    for threads in ["1", "2", "0"] {
        let mut b = vec![
            "contour",
            &input,
            "-o",
            "b.geojson",
            "--interval",
            "50",
            "-q",
        ];
        b.extend_from_slice(&tiles);
        b.extend_from_slice(&["--threads", threads]);
        run_ok(&d, &b);
        let (fa, fb) = (
            features(&d.path("a.geojson")),
            features(&d.path("b.geojson")),
        );
        assert!(fa.len() > 10, "{} lines", fa.len());
        assert_eq!(canonical(fa), canonical(fb), "{threads} threads");
        std::fs::remove_file(d.path("b.geojson")).unwrap();
    }
    // The same TIN not shaped for the levels: same bound, more segments.
    let mut m = vec!["mesh", &input, "-o", "plain.ply", "-q"];
    m.extend_from_slice(&tiles);
    run_ok(&d, &m);
    let contour_of = |mesh: &str, out: &str| {
        let a = [
            "contour",
            &input,
            "-o",
            out,
            "--interval",
            "50",
            "--mesh",
            mesh,
            "-q",
        ];
        run_ok(&d, &a);
        features(&d.path(out))
            .iter()
            .map(|(_, points)| points.len() - 1)
            .sum::<usize>()
    };
    let (shaped, plain) = (
        contour_of("m.ply", "s.geojson"),
        contour_of("plain.ply", "p.geojson"),
    );
    assert!(
        shaped * 100 <= plain * 97,
        "{shaped} segments shaped, {plain} plain"
    );
}

#[test]
fn decimated_contours_have_fewer_segments_than_the_full_grid() {
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let segments = |name: &str| -> usize {
        features(&d.path(name))
            .iter()
            .map(|(_, p)| p.len() - 1)
            .sum()
    };
    run_ok(
        &d,
        &["contour", &input, "-o", "full.geojson", "--interval", "100"],
    );
    run_ok(
        &d,
        &[
            "contour",
            &input,
            "-o",
            "tin.geojson",
            "--interval",
            "100",
            "--max-error",
            "10",
        ],
    );
    let (full, tin) = (segments("full.geojson"), segments("tin.geojson"));
    // 25,984 vs 84,451 with the default decimation; docs/results.md has the numbers on real
    // DEMs.
    assert!(
        tin < full,
        "{tin} segments on the TIN vs {full} on the grid"
    );
}

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 == 0.0 {
        0.0
    } else {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

#[test]
fn simplify_keeps_a_subsequence_within_the_distance() {
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let d = Dir::new();
    let base = [
        "contour",
        &input,
        "--interval",
        "100",
        "--max-error",
        "10",
        "--geojson-source-crs",
    ];
    let mut a = base.to_vec();
    a.extend_from_slice(&["-o", "exact.geojson"]);
    run_ok(&d, &a);
    let mut b = base.to_vec();
    b.extend_from_slice(&["-o", "simple.geojson", "--simplify", "25"]);
    run_ok(&d, &b);
    let (exact, simple) = (
        features(&d.path("exact.geojson")),
        features(&d.path("simple.geojson")),
    );
    assert_eq!(exact.len(), simple.len());
    let count = |f: &[(f64, Vec<[f64; 2]>)]| f.iter().map(|(_, p)| p.len() - 1).sum::<usize>();
    assert!(
        count(&simple) * 2 < count(&exact),
        "{} segments simplified vs {} exact",
        count(&simple),
        count(&exact)
    );
    for ((le, pe), (ls, ps)) in exact.iter().zip(&simple) {
        assert_eq!(le, ls);
        assert_eq!((pe.first(), pe.last()), (ps.first(), ps.last()));
        assert!(ps.len() >= if pe.first() == pe.last() { 4 } else { 2 });
        // A subsequence, and each run of dropped points within 25 m of its segment.
        let mut k = 0;
        for w in ps.windows(2) {
            let start = k;
            while pe[k] != w[1] || k == start {
                k += 1;
            }
            assert_eq!(pe[start], w[0]);
            for &p in &pe[start..=k] {
                assert!(segment_distance(p, w[0], w[1]) <= 25.0);
            }
        }
    }
}

#[test]
fn levels_whose_lines_would_not_fit_in_memory_are_refused_up_front() {
    // A 120 x 100 checkerboard of 0 and 99,000 contoured every 1: 99,000 levels, each
    // crossing every triangle, about 2.3e9 segments (over 100 GB of lines). Refused
    // before contouring, naming the file, with nothing written.
    let d = Dir::new();
    let mut asc = String::from("ncols 120\nnrows 100\nxllcorner 0\nyllcorner 0\ncellsize 1\n");
    for row in 0..100 {
        let values: Vec<&str> = (0..120)
            .map(|col| if (row + col) % 2 == 0 { "0" } else { "99000" })
            .collect();
        asc.push_str(&values.join(" "));
        asc.push('\n');
    }
    d.write("board.asc", &asc);
    let o = d.run(&["contour", "board.asc", "-o", "c.fgb", "--interval", "1"]);
    assert_fails_naming(&o, &["board.asc", "levels cross the TIN", "--interval"]);
    assert!(!d.path("c.fgb").exists());
}

#[test]
fn a_memory_ulimit_counts_as_what_is_available() {
    // The check read only /proc/meminfo: under `ulimit -v` (or a container's cgroup limit)
    // the sample DEM contoured every 0.1 m (88 M segments, ~5.7 GB) aborted with
    // "memory allocation failed" instead of being refused.
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = run_under_ulimit(
        &d,
        1_500_000,
        &["contour", &dem, "-o", "c.fgb", "--interval", "0.1"],
    );
    assert_fails_naming(&o, &["becmodel", "levels cross the TIN", "GB is available"]);
    assert!(!d.path("c.fgb").exists());
}

#[test]
fn tiled_lines_that_outgrow_memory_stop_the_run() {
    // Tiles are contoured as they are finished and only the lines are held, so the check
    // runs as they grow: the sample DEM at ε = 0.5 in tiles of 128, contoured every 0.1 m,
    // makes lines beyond a 1.5 GB ulimit partway through and is stopped there. With 20
    // worker threads (one per tile) their own memory counts too: measured once at the
    // start, the run aborted on a failed allocation instead.
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = run_under_ulimit(
        &d,
        1_500_000,
        &[
            "contour",
            &dem,
            "-o",
            "c.fgb",
            "--interval",
            "0.1",
            "--max-error",
            "0.5",
            "--tile-size",
            "128",
            "--threads",
            "20",
        ],
    );
    assert_fails_naming(
        &o,
        &[
            "becmodel",
            "levels cross the TIN about",
            "times or more",
            "GB is available",
        ],
    );
    assert!(!d.path("c.fgb").exists());
}

#[test]
fn contour_bad_input_fails_cleanly() {
    let dem = fixture("tintn_valid_raster_3857.tif");
    let d = Dir::new();
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["nope.tif", "-o", "c.geojson", "--interval", "1"],
            vec!["nope.tif"],
        ),
        (vec![&dem, "-o", "c.shp", "--interval", "1"], vec!["c.shp"]),
        (
            vec![&dem, "-o", "no/dir/c.fgb", "--interval", "1"],
            vec!["no/dir/c.fgb"],
        ),
        (vec![&dem, "-o", "c.geojson"], vec!["--interval"]),
        (
            vec![
                &dem,
                "-o",
                "c.geojson",
                "--interval",
                "1",
                "--simplify",
                "0",
            ],
            vec!["--simplify"],
        ),
        (
            vec![
                &dem,
                "-o",
                "c.fgb",
                "--interval",
                "1",
                "--geojson-source-crs",
            ],
            vec!["c.fgb", "--geojson-source-crs"],
        ),
        (
            vec![&dem, "-o", "c.geojson", "--interval", "0"],
            vec!["--interval"],
        ),
        (
            vec![&dem, "-o", "c.geojson", "--interval", "1", "--levels", "3"],
            vec!["--levels"],
        ),
        (
            vec![&dem, "-o", "c.geojson", "--levels", "3,x"],
            vec!["--levels"],
        ),
        (
            vec![&dem, "-o", "c.geojson", "--interval", "1e-9"],
            vec!["levels"],
        ),
        (
            // Levels beyond f64's integers: this used to loop forever.
            vec![
                &dem,
                "-o",
                "c.geojson",
                "--interval",
                "10",
                "--offset",
                "1e17",
            ],
            vec!["f64 cannot tell the levels apart"],
        ),
        (
            vec![
                &dem,
                "-o",
                "c.geojson",
                "--interval",
                "1",
                "--max-error",
                "-1",
            ],
            vec!["--max-error"],
        ),
        (
            vec![
                &dem,
                "-o",
                "c.geojson",
                "--interval",
                "1",
                "--mesh",
                "gone.ply",
            ],
            vec!["gone.ply"],
        ),
        (
            vec![
                &dem,
                "-o",
                "c.geojson",
                "--interval",
                "1",
                "--mesh",
                "m.ply",
                "--max-error",
                "1",
            ],
            vec!["--mesh"],
        ),
    ];
    for (args, names) in cases {
        let mut a = vec!["contour"];
        a.extend_from_slice(&args);
        let o = d.run(&a);
        assert_fails_naming(&o, &names);
        assert!(d.files().is_empty(), "{args:?} left {:?}", d.files());
    }
    // A mesh made from another raster: its vertices are not on this raster's samples.
    let other = fixture("becmodel_dem_bc_albers_50m.tif");
    run_ok(&d, &["mesh", &other, "-o", "m.ply", "--max-error", "50"]);
    let o = d.run(&[
        "contour",
        &dem,
        "-o",
        "c.geojson",
        "--interval",
        "1",
        "--mesh",
        "m.ply",
    ]);
    assert_fails_naming(&o, &["m.ply", "vertex"]);
    assert_eq!(d.files(), vec!["m.ply"]);
}

#[test]
fn wgs84_geojson_is_cut_at_the_antimeridian() {
    // A cone centred on 180° E in a raster on 170..190° longitudes (WGS84): its rings cross
    // the antimeridian twice each. RFC 7946 wants longitudes in [-180, 180] and no segment
    // running the long way round; FlatGeobuf keeps the raster's coordinates uncut.
    let d = Dir::new();
    write_cone_across_180(&d);
    for out in ["c.geojson", "c.fgb"] {
        run_ok(
            &d,
            &["contour", "cone.asc", "--interval", "15", "-o", out, "-q"],
        );
    }
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("c.geojson")).unwrap()).unwrap();
    let features = v["features"].as_array().unwrap();
    let mut cut = 0;
    for f in features {
        let geometry = &f["geometry"];
        let parts: Vec<Vec<[f64; 2]>> = match geometry["type"].as_str().unwrap() {
            "LineString" => vec![serde_json::from_value(geometry["coordinates"].clone()).unwrap()],
            "MultiLineString" => {
                cut += 1;
                serde_json::from_value(geometry["coordinates"].clone()).unwrap()
            }
            other => panic!("unexpected geometry {other}"),
        };
        for part in &parts {
            assert!(part.len() >= 2);
            assert!(
                part.iter().all(|p| (-180.0..=180.0).contains(&p[0])),
                "{part:?}"
            );
            for pair in part.windows(2) {
                assert!((pair[1][0] - pair[0][0]).abs() < 5.0, "{pair:?}");
            }
        }
        if parts.len() > 1 {
            // Every cut ends a part on one side of 180° and starts the next on the other
            // at the same latitude.
            let ends: Vec<[f64; 2]> = parts
                .iter()
                .flat_map(|p| [p[0], p[p.len() - 1]])
                .filter(|p| p[0].abs() == 180.0)
                .collect();
            assert_eq!(ends.len() % 2, 0, "{parts:?}");
            for e in &ends {
                assert!(
                    ends.iter().any(|o| o[0] == -e[0] && o[1] == e[1]),
                    "{e:?} has no partner across 180°: {parts:?}"
                );
            }
        }
    }
    // The rings at 90, 75 and 60 close around 180° and are cut; lower levels reach the
    // raster's top and bottom rows in arcs on either side.
    assert!(cut >= 3, "{cut} of {} features cut", features.len());
    // GDAL reads both files with the same features; the FlatGeobuf is uncut.
    let geojson = ogrinfo(&d.path("c.geojson"));
    let fgb = ogrinfo(&d.path("c.fgb"));
    let count = format!("Feature Count: {}\n", features.len());
    assert!(geojson.contains(&count), "{geojson}");
    assert!(fgb.contains(&count), "{fgb}");
    assert!(fgb.contains("Geometry: Line String"), "{fgb}");
    assert!(fgb.contains("Extent: (170.25"), "{fgb}");
}

/// An ESRI `.prj` for WGS84 longitude, latitude (GDAL reads it beside an `.asc`).
const WGS84_PRJ: &str = "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",\
    6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"Degree\",0.017453292519943295]]";

/// `cone.asc` (+ `.prj`, WGS84) in `d`: a cone of height 100 centred on 180° E, 0° N, in a
/// raster on 170.25..190.25° longitudes (none on 180), one sample per degree.
fn write_cone_across_180(d: &Dir) {
    let mut asc =
        String::from("ncols 21\nnrows 11\nxllcorner 169.75\nyllcorner -5.5\ncellsize 1\n");
    for row in 0..11 {
        let lat = 5.0 - row as f64;
        let values: Vec<String> = (0..21)
            .map(|col| {
                let lon = 170.25 + col as f64;
                format!(
                    "{}",
                    100.0 - 10.0 * ((lon - 180.0).powi(2) + lat * lat).sqrt()
                )
            })
            .collect();
        asc.push_str(&values.join(" "));
        asc.push('\n');
    }
    d.write("cone.asc", &asc);
    d.write("cone.prj", WGS84_PRJ);
}

#[test]
fn wgs84_geojson_meshes_across_the_antimeridian_verify_and_contour() {
    // Triangles across 180° are written cut in two (MultiPolygon) with longitudes in
    // [-180, 180]; verify and contour --mesh read them back onto the raster's 170..190.
    let d = Dir::new();
    write_cone_across_180(&d);
    for out in ["m.geojson", "m.ply"] {
        let args = ["mesh", "cone.asc", "--max-error", "0.5", "-o", out, "-q"];
        run_ok(&d, &args);
    }
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("m.geojson")).unwrap()).unwrap();
    let multi = v["features"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["geometry"]["type"] == "MultiPolygon")
        .count();
    assert!(multi > 0, "no triangle cut");
    let text = v["features"].to_string();
    assert!(
        !text.contains("[181") && !text.contains("[190"),
        "longitudes beyond 180"
    );
    let o = d.run(&["verify", "cone.asc", "m.geojson", "--max-error", "0.5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The same lines as from the same mesh in PLY (the contour's GeoJSON in the raster's
    // own EPSG:4326, so cut at the antimeridian alike; the parts are compared).
    for (mesh, out) in [("m.geojson", "a.geojson"), ("m.ply", "b.geojson")] {
        let args = [
            "contour",
            "cone.asc",
            "--interval",
            "15",
            "--mesh",
            mesh,
            "-o",
            out,
        ];
        let mut args = args.to_vec();
        args.extend(["--geojson-source-crs", "-q"]);
        run_ok(&d, &args);
    }
    let (a, b) = (
        line_parts(&d.path("a.geojson")),
        line_parts(&d.path("b.geojson")),
    );
    assert!(!a.is_empty());
    assert_eq!(canonical(a), canonical(b));
}

/// Every part of every (Multi)LineString of a GeoJSON file we wrote, as (elev, points).
fn line_parts(path: &std::path::Path) -> Vec<(f64, Vec<[f64; 2]>)> {
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let mut parts = Vec::new();
    for f in v["features"].as_array().unwrap() {
        let elev = f["properties"]["elev"].as_f64().unwrap();
        let coordinates = f["geometry"]["coordinates"].clone();
        match f["geometry"]["type"].as_str() {
            Some("LineString") => parts.push((elev, serde_json::from_value(coordinates).unwrap())),
            Some("MultiLineString") => {
                let lines: Vec<Vec<[f64; 2]>> = serde_json::from_value(coordinates).unwrap();
                parts.extend(lines.into_iter().map(|line| (elev, line)));
            }
            other => panic!("{other:?}"),
        }
    }
    parts
}

#[test]
fn a_projected_raster_across_the_antimeridian_round_trips_through_wgs84_geojson() {
    // UTM zone 1N (central meridian 177° W) at 60° N: eastings 280..380 km span 180°.
    // PROJ gives longitudes on both sides; the GeoJSON mesh is cut and still verifies
    // after the transformation back, and contour lines across 180° are cut too.
    let d = Dir::new();
    let mut asc =
        String::from("ncols 50\nnrows 50\nxllcorner 280000\nyllcorner 6650000\ncellsize 2000\n");
    for row in 0..50 {
        let values: Vec<String> = (0..50)
            .map(|col| format!("{}", ((col * 7 + row * 3) % 23) as f64 + 0.1 * col as f64))
            .collect();
        asc.push_str(&values.join(" "));
        asc.push('\n');
    }
    d.write("utm.asc", &asc);
    d.write(
        "utm.vrt",
        "<VRTDataset rasterXSize=\"50\" rasterYSize=\"50\"><SRS>EPSG:32601</SRS>\
         <GeoTransform>280000, 2000, 0, 6750000, 0, -2000</GeoTransform>\
         <VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource>\
         <SourceFilename relativeToVRT=\"1\">utm.asc</SourceFilename>\
         <SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>",
    );
    run_ok(
        &d,
        &[
            "mesh",
            "utm.vrt",
            "--max-error",
            "2",
            "-o",
            "m.geojson",
            "-q",
        ],
    );
    let kinds = |name: &str| -> Vec<String> {
        let v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.path(name)).unwrap()).unwrap();
        v["features"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["geometry"]["type"].as_str().unwrap().to_owned())
            .collect()
    };
    assert!(kinds("m.geojson").iter().any(|k| k == "MultiPolygon"));
    let o = d.run(&["verify", "utm.vrt", "m.geojson", "--max-error", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    run_ok(
        &d,
        &[
            "contour",
            "utm.vrt",
            "--interval",
            "5",
            "-o",
            "c.geojson",
            "-q",
        ],
    );
    assert!(kinds("c.geojson").iter().any(|k| k == "MultiLineString"));
    let info = ogrinfo(&d.path("c.geojson"));
    assert!(info.contains("Extent: (-180.000000,"), "{info}");
}

/// A 40 x 40 raster of 10 km cells around (0, 0) of `srs`, with a wavy surface.
fn write_projected(d: &Dir, name: &str, srs: &str, x0: f64, y0: f64) {
    let mut asc = format!(
        "ncols 40\nnrows 40\nxllcorner {x0}\nyllcorner {}\ncellsize 10000\n",
        y0 - 400_000.0
    );
    for row in 0..40 {
        let values: Vec<String> = (0..40)
            .map(|col| {
                let (x, y) = (f64::from(col), f64::from(row));
                format!("{}", 50.0 * (x / 5.0).sin() * (y / 4.0).cos() + x)
            })
            .collect();
        asc.push_str(&values.join(" "));
        asc.push('\n');
    }
    d.write(&format!("{name}.asc"), &asc);
    d.write(
        &format!("{name}.vrt"),
        &format!(
            "<VRTDataset rasterXSize=\"40\" rasterYSize=\"40\"><SRS>{srs}</SRS>\
             <GeoTransform>{x0}, 10000, 0, {y0}, 0, -10000</GeoTransform>\
             <VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource>\
             <SourceFilename relativeToVRT=\"1\">{name}.asc</SourceFilename>\
             <SourceBand>1</SourceBand></SimpleSource></VRTRasterBand></VRTDataset>"
        ),
    );
}

#[test]
fn a_polar_raster_contours_to_wgs84_and_its_mesh_needs_its_own_crs() {
    // Polar stereographic around the north pole: longitudes go all the way round, so no
    // frame is continuous. Contour lines are unwrapped along each line and cut at 180°
    // (they used to jump to -180 at about 133° E); a GeoJSON mesh is refused up front
    // (triangles round the pole cannot be written in longitude, latitude), and written in
    // the raster's CRS with --geojson-source-crs.
    let d = Dir::new();
    write_projected(&d, "arctic", "EPSG:3413", -200_000.0, 200_000.0);
    run_ok(
        &d,
        &[
            "contour",
            "arctic.vrt",
            "--interval",
            "10",
            "-o",
            "c.geojson",
            "-q",
        ],
    );
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("c.geojson")).unwrap()).unwrap();
    let mut segments = 0;
    for f in v["features"].as_array().unwrap() {
        let g = &f["geometry"];
        let parts: Vec<&serde_json::Value> = match g["type"].as_str().unwrap() {
            "LineString" => vec![&g["coordinates"]],
            _ => g["coordinates"].as_array().unwrap().iter().collect(),
        };
        for part in parts {
            let p: Vec<[f64; 2]> = part
                .as_array()
                .unwrap()
                .iter()
                .map(|q| [q[0].as_f64().unwrap(), q[1].as_f64().unwrap()])
                .collect();
            for w in p.windows(2) {
                assert!(w[0][0].abs() <= 180.0 && w[1][0].abs() <= 180.0);
                assert!(
                    (w[0][0] - w[1][0]).abs() < 90.0,
                    "a jump {:?} -> {:?}",
                    w[0],
                    w[1]
                );
                segments += 1;
            }
        }
    }
    assert!(segments > 1000, "{segments} segments");

    for args in [
        &["--max-error", "1"][..],
        &["--max-error", "1", "--tile-size", "16"],
    ] {
        let mut all = vec!["mesh", "arctic.vrt", "-o", "m.geojson"];
        all.extend_from_slice(args);
        assert_fails_naming(
            &d.run(&all),
            &["m.geojson", "north pole", "--geojson-source-crs"],
        );
        assert!(!d.path("m.geojson").exists());
    }
    run_ok(
        &d,
        &[
            "mesh",
            "arctic.vrt",
            "-o",
            "m.geojson",
            "--max-error",
            "1",
            "--geojson-source-crs",
            "-q",
        ],
    );
    let o = d.run(&["verify", "arctic.vrt", "m.geojson", "--max-error", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_mercator_raster_past_the_antimeridian_is_not_written_as_wgs84_geojson() {
    // Web Mercator eastings past 20037508 m: PROJ takes them back to the other side of
    // the world, so WGS84 coordinates would not read back to their samples.
    let d = Dir::new();
    write_projected(&d, "merc", "EPSG:3857", 19_837_508.34, 1_000_000.0);
    assert_fails_naming(
        &d.run(&["mesh", "merc.vrt", "-o", "m.geojson", "--max-error", "1"]),
        &["m.geojson", "comes back from WGS84", "--geojson-source-crs"],
    );
    assert!(!d.path("m.geojson").exists());
    run_ok(
        &d,
        &["mesh", "merc.vrt", "-o", "m.fgb", "--max-error", "1", "-q"],
    );
    let o = d.run(&["verify", "merc.vrt", "m.fgb", "--max-error", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn global_grids_with_both_edge_meridians_round_trip_through_wgs84_geojson() {
    // 5° global grids whose first and last columns are the same meridian (-180 and 180, or
    // 0 and 360), meshed coarsely enough for triangles wider than 180° of longitude: the
    // GeoJSON mesh still verifies (edge vertices are not merged, wide triangles are not
    // taken the short way round).
    let d = Dir::new();
    for (name, xll) in [("pm180", -182.5), ("zero360", -2.5)] {
        let mut asc = format!("ncols 73\nnrows 37\nxllcorner {xll}\nyllcorner -92.5\ncellsize 5\n");
        for row in 0..37 {
            let lat = 90.0 - 5.0 * row as f64;
            let values: Vec<String> = (0..73)
                .map(|col| {
                    let lon = xll + 2.5 + 5.0 * col as f64;
                    let v = 1000.0 * (3.0 * lon.to_radians()).sin() * lat.to_radians().cos()
                        + 300.0 * (4.0 * lat.to_radians()).cos();
                    format!("{v:.3}")
                })
                .collect();
            asc.push_str(&values.join(" "));
            asc.push('\n');
        }
        d.write(&format!("{name}.asc"), &asc);
        d.write(&format!("{name}.prj"), WGS84_PRJ);
        let input = format!("{name}.asc");
        // Not on 0..360 at 200 triangles: there a triangle joins the south pole's samples
        // in the first and last columns (0 and 360, both written as longitude 0), which
        // the file cannot tell apart; the conformity check of `verify` rejects the
        // read-back (a known limitation, docs/architecture.md).
        let targets: &[[&str; 2]] = match name {
            "pm180" => &[
                ["--max-triangles", "12"],
                ["--max-triangles", "200"],
                ["--max-error", "100"],
            ],
            _ => &[["--max-triangles", "12"], ["--max-error", "100"]],
        };
        for target in targets {
            let mut args = vec!["mesh", input.as_str(), "-o", "m.geojson", "-q"];
            args.extend(target.iter().copied());
            run_ok(&d, &args);
            let o = d.run(&["verify", &input, "m.geojson"]);
            assert!(o.status.success(), "{name} {target:?}: {}", stderr(&o));
        }
    }
}

#[test]
fn a_column_a_hair_off_180_is_put_on_it_in_wgs84_geojson() {
    // A column whose centre the geotransform puts at 179.9999999999998 (as ETOPO5's on
    // 0..360): written on 180, so triangles beside it are not cut into slivers; it still
    // verifies.
    let d = Dir::new();
    let mut asc =
        String::from("ncols 6\nnrows 5\nxllcorner 177.4999999999998\nyllcorner -2.5\ncellsize 1\n");
    for row in 0..5 {
        let values: Vec<String> = (0..6)
            .map(|col| format!("{}", (col * col + 3 * row) as f64 * 1.5))
            .collect();
        asc.push_str(&values.join(" "));
        asc.push('\n');
    }
    d.write("hair.asc", &asc);
    d.write("hair.prj", WGS84_PRJ);
    // The raster's own EPSG:4326 with --geojson-source-crs is RFC 7946 too, snapped alike
    // (it was cut into slivers), for meshes and contour lines.
    for flags in [&[][..], &["--geojson-source-crs"][..]] {
        let mesh = [
            "mesh",
            "hair.asc",
            "--max-error",
            "0",
            "-o",
            "m.geojson",
            "-q",
        ];
        run_ok(&d, &[&mesh[..], flags].concat());
        let text = std::fs::read_to_string(d.path("m.geojson")).unwrap();
        assert!(!text.contains("179.9999999999998"), "{flags:?} {text}");
        assert!(
            text.contains("[180.0,") && text.contains("[-180.0,"),
            "{flags:?} {text}"
        );
        assert!(!text.contains("MultiPolygon"), "{flags:?} {text}");
        let o = d.run(&["verify", "hair.asc", "m.geojson", "--max-error", "0"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let contour = [
            "contour",
            "hair.asc",
            "--levels",
            "10",
            "-o",
            "c.geojson",
            "-q",
        ];
        run_ok(&d, &[&contour[..], flags].concat());
        let text = std::fs::read_to_string(d.path("c.geojson")).unwrap();
        assert!(!text.contains("179.9999999999998"), "{flags:?} {text}");
    }
}

/// An ESRI ASCII grid `n x n` of `f(column, row)` (`None`: nodata), in pixel units.
fn ascii_grid(d: &Dir, name: &str, n: usize, f: impl Fn(usize, usize) -> Option<f64>) {
    let mut text =
        format!("ncols {n}\nnrows {n}\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n");
    for r in 0..n {
        let row: Vec<String> = (0..n)
            .map(|c| f(c, r).map_or("-9999".to_owned(), |v| v.to_string()))
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write(name, &text);
}

#[test]
fn a_mesh_file_must_be_the_rasters() {
    // A mesh of a tilted plane (two triangles at a bound of 1), contoured with rasters it
    // was not written from: a hole under its triangles, or other heights at its vertices.
    // Both used to give lines that are not the raster's (through the hole, or at the
    // mesh's own heights), exit 0.
    let d = Dir::new();
    let plane = |c: usize, r: usize| 2.0 * c as f64 + r as f64;
    ascii_grid(&d, "plane.asc", 20, |c, r| Some(plane(c, r)));
    let holed =
        |c: usize, r: usize| (!(8..12).contains(&c) || !(8..12).contains(&r)).then(|| plane(c, r));
    ascii_grid(&d, "holed.asc", 20, holed);
    ascii_grid(&d, "raised.asc", 20, |c, r| Some(plane(c, r) + 1.0));
    run_ok(
        &d,
        &[
            "mesh",
            "plane.asc",
            "-o",
            "plane.ply",
            "--max-error",
            "1",
            "-q",
        ],
    );
    let contour = |input: &str| {
        d.run(&[
            "contour",
            input,
            "--mesh",
            "plane.ply",
            "-o",
            "c.geojson",
            "--interval",
            "5",
        ])
    };
    assert_fails_naming(
        &contour("holed.asc"),
        &["plane.ply", "not a valid triangulation", "nodata"],
    );
    assert_fails_naming(
        &contour("raised.asc"),
        &["plane.ply", "vertex", "needs a TIN of this raster"],
    );
    assert!(!d.path("c.geojson").exists());
    run_ok(
        &d,
        &[
            "contour",
            "plane.asc",
            "--mesh",
            "plane.ply",
            "-o",
            "c.geojson",
            "--interval",
            "5",
            "-q",
        ],
    );
}

#[test]
fn no_line_at_all_is_a_readable_empty_layer() {
    // A level above every height: zero features. The FlatGeobuf announced a spatial index
    // over no feature, which GDAL refused to open ("Number of items must be greater than 0").
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    for out in ["none.fgb", "none.geojson"] {
        run_ok(
            &d,
            &["contour", &dem, "-o", out, "--levels", "100000", "-q"],
        );
        let info = ogrinfo(&d.path(out));
        assert!(info.contains("Feature Count: 0"), "{out}: {info}");
    }
}

#[test]
fn geojson_is_refused_for_a_raster_past_the_pole_and_numbers_read_well() {
    let d = Dir::new();
    // Sample centres up to latitude 91.5 in EPSG:4326: written as such before, exit 0.
    let mut text = "ncols 30\nnrows 20\nxllcorner -10\nyllcorner 72\ncellsize 1\n".to_owned();
    for r in 0..20 {
        let row: Vec<String> = (0..30).map(|c| (3 * c + 2 * r).to_string()).collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write("north.asc", &text);
    d.write("north.prj", "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]");
    let o = d.run(&[
        "contour",
        "north.asc",
        "-o",
        "c.geojson",
        "--interval",
        "10",
    ]);
    assert_fails_naming(&o, &["c.geojson", "latitude 91.5", ".fgb"]);
    let o = d.run(&["mesh", "north.asc", "-o", "m.geojson", "--max-error", "1"]);
    assert_fails_naming(&o, &["m.geojson", "latitude 91.5"]);
    run_ok(
        &d,
        &[
            "contour",
            "north.asc",
            "-o",
            "c.fgb",
            "--interval",
            "10",
            "-q",
        ],
    );
    // Numbers in messages: an exponent rather than three hundred digits; a negative
    // interval refused as a value (clap took "-10" for a flag before).
    let o = d.run(&[
        "contour",
        "north.asc",
        "-o",
        "x.fgb",
        "--interval",
        "1e-300",
    ]);
    assert_fails_naming(&o, &["interval 1e-300", "levels"]);
    assert!(stderr(&o).len() < 300, "{}", stderr(&o));
    let o = d.run(&["contour", "north.asc", "-o", "x.fgb", "--interval", "-10"]);
    assert_fails_naming(&o, &["--interval", "-10", "> 0"]);
    assert_eq!(
        d.files()
            .iter()
            .filter(|f| f.starts_with(['c', 'm', 'x']))
            .count(),
        1
    );
}

#[test]
fn a_float32_mesh_file_of_fractional_heights_is_the_rasters() {
    // STL and glTF store heights as float32 offsets from a local origin: read back they
    // are neither the sample nor its float32 rounding, and were refused.
    let d = Dir::new();
    ascii_grid(&d, "hill.asc", 30, |c, r| {
        let (x, y) = (c as f64 - 14.3, r as f64 - 15.7);
        Some(3019.244384765625 + 40.0 * (-(x * x + y * y) / 60.0).exp() + 0.01 * x)
    });
    for mesh in ["hill.stl", "hill.glb"] {
        run_ok(
            &d,
            &["mesh", "hill.asc", "-o", mesh, "--max-error", "0.5", "-q"],
        );
        run_ok(
            &d,
            &[
                "contour",
                "hill.asc",
                "--mesh",
                mesh,
                "-o",
                "c.fgb",
                "--interval",
                "5",
                "-q",
            ],
        );
    }
}

/// A Float64 raster (raw samples behind a VRT, UTM 32N, 1 m pixels at easting 500,000)
/// written into `d` as `name.vrt`; `values` row-major, `width` per row.
fn float64_utm(d: &Dir, name: &str, width: usize, values: &[f64]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(d.path(&format!("{name}.raw")), bytes).unwrap();
    let height = values.len() / width;
    d.write(
        &format!("{name}.vrt"),
        &format!(
            "<VRTDataset rasterXSize=\"{width}\" rasterYSize=\"{height}\"><SRS>EPSG:32632</SRS>\
             <GeoTransform>500000, 1, 0, 5000000, 0, -1</GeoTransform>\
             <VRTRasterBand dataType=\"Float64\" band=\"1\" subClass=\"VRTRawRasterBand\">\
             <SourceFilename relativeToVRT=\"1\">{name}.raw</SourceFilename>\
             <ImageOffset>0</ImageOffset><PixelOffset>8</PixelOffset>\
             <LineOffset>{}</LineOffset><ByteOrder>LSB</ByteOrder></VRTRasterBand></VRTDataset>",
            8 * width
        ),
    );
    format!("{name}.vrt")
}

#[test]
fn lines_have_no_repeated_points_in_map_coordinates() {
    // Crossings within ~1e-14 of a sample are distinct in the grid but land on the same
    // map coordinate 500,000 m from the origin: a pit one ulp below the level gave a ring
    // of 7 identical points (length 0, invalid), and a bowl whose heights were summed in
    // steps of 0.1 gave rings with dozens of zero-length segments.
    let d = Dir::new();
    let mut pit = vec![101.0; 25];
    pit[12] = 100f64.next_down();
    let pit = float64_utm(&d, "pit", 5, &pit);
    let mut bowl = Vec::new();
    for y in 0..40 {
        for x in 0..40 {
            let r = f64::hypot(f64::from(x) - 19.5, f64::from(y) - 19.5);
            let mut h = 98.0;
            for _ in 0..(r * 3.0).round() as usize {
                h += 0.1;
            }
            bowl.push(h);
        }
    }
    let bowl = float64_utm(&d, "bowl", 40, &bowl);
    for (input, levels, rings) in [(&bowl, "100,101,102", 3), (&pit, "100", 0)] {
        for crs in [&["--geojson-source-crs"][..], &[]] {
            let mut args = vec!["contour", input, "-o", "c.geojson", "--levels", levels];
            args.extend_from_slice(crs);
            run_ok(&d, &args);
            let lines = features(&d.path("c.geojson"));
            assert_eq!(lines.len(), rings, "{input} {crs:?}");
            for (level, points) in lines {
                assert!(
                    points.windows(2).all(|w| w[0] != w[1]),
                    "{input} {crs:?}: a repeated point at level {level}: {points:?}"
                );
                assert!(points.len() >= 4 && points[0] == points[points.len() - 1]);
            }
        }
    }
}

#[test]
fn empty_output_says_why_and_a_mesh_of_another_band_suggests_band() {
    // A level outside the heights succeeded silently with no line (a typo looked like
    // success); a --mesh written from band 2 and contoured with band 1 hinted only at
    // --pixel-coords.
    let d = Dir::new();
    let dem = fixture("becmodel_dem_bc_albers_50m.tif");
    for (levels, why) in [
        (
            &["--levels", "10000"][..],
            "the levels miss the TIN's heights, 350 .. 2583",
        ),
        (
            &["--interval", "5000"],
            "no level of the --interval lies within the TIN's heights",
        ),
        // The highest sample only touches its level: within the range, yet no line.
        (&["--levels", "2583"], "no level crosses the TIN"),
    ] {
        let o = d.run(&[&["contour", &dem, "-o", "c.geojson"], levels].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stderr(&o).contains(why), "{levels:?}: {}", stderr(&o));
    }
    let o = d.run(&["contour", &dem, "-o", "c.geojson", "--interval", "1e300"]);
    assert!(stderr(&o).contains("at 0 levels") && stderr(&o).len() < 400);
    let o = d.run(&[
        "contour",
        &dem,
        "-o",
        "c.geojson",
        "--interval",
        "100",
        "--max-error",
        "1e300",
    ]);
    assert!(stderr(&o).contains("TIN within 1e300"), "{}", stderr(&o));

    let vrt = format!(
        "<VRTDataset rasterXSize=\"430\" rasterYSize=\"516\">\
         <VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource><SourceFilename>{dem}\
         </SourceFilename><SourceBand>1</SourceBand></SimpleSource></VRTRasterBand>\
         <VRTRasterBand dataType=\"Float32\" band=\"2\"><ComplexSource><SourceFilename>{dem}\
         </SourceFilename><SourceBand>1</SourceBand><ScaleOffset>5</ScaleOffset>\
         </ComplexSource></VRTRasterBand></VRTDataset>"
    );
    d.write("two.vrt", &vrt);
    run_ok(
        &d,
        &[
            "mesh",
            "two.vrt",
            "--band",
            "2",
            "-o",
            "b2.ply",
            "--max-error",
            "5",
            "--pixel-coords",
            "-q",
        ],
    );
    let o = d.run(&[
        "contour",
        "two.vrt",
        "-o",
        "c.fgb",
        "--interval",
        "100",
        "--mesh",
        "b2.ply",
        "--pixel-coords",
    ]);
    assert_fails_naming(&o, &["b2.ply", "band 1 of", "--band"]);
}
