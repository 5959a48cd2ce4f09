//! `tinsmith tiles INPUT --base RASTER`: a regional raster over a coarser one of a wider
//! extent, decoded by the independent decoder and measured against GDAL's own warp of
//! both rasters in priority order into each tile's lattice.

use std::collections::{BTreeMap, BTreeSet};

use std::process::Command;

use crate::shards::{check_shards, differences, identities, pyramid_files, run_ok};
use crate::tiles::{
    all_files, ascii_grid, check_shared_edges, check_tile, decode_pyramid, egm96_undulations,
    layer_json, max_error, stacked_gdal_samples, Tile, Tiling,
};
use crate::util::{assert_fails_naming, stderr, Dir};

/// The input's extent: west, south, east, north.
const HIGH: [f64; 4] = [9.6, 44.3, 10.6, 45.1];

/// The base's own level: the first whose sample spacing (180° / 2^z / the cells of a
/// tile's lattice) is at most its 0.05°: level 5 with 151 cells (0.037°, the coarser of
/// the two lattices' own levels; 217 cells would give 0.026°).
const BASE_LEVEL: u32 = 5;

/// The input's hole of nodata: centre longitude, latitude and radius (degrees).
const HOLE: [f64; 3] = [10.1, 44.7, 0.1];

/// Whether a point lies within three of the input's 0.005° pixels of its hole's rim. There
/// GDAL and tinsmith read the input differently, both fairly: GDAL drops a point whose own
/// pixel is nodata (so the base shows through), tinsmith interpolates it from the valid
/// pixels of the four around it (as it does for one input, where GDAL's nodata is not
/// compared).
fn near_the_rim(lon: f64, lat: f64) -> bool {
    ((lon - HOLE[0]).hypot(lat - HOLE[1]) - HOLE[2]).abs() < 0.015
}

/// A 0.05° base over 5..15°E, 40..48°N and a 0.005° input over [`HIGH`] with a hole of
/// nodata: their paths.
fn inputs(dir: &Dir) -> (String, String) {
    let low = ascii_grid(dir, "low.asc", (5.0, 40.0, 0.05), (200, 160), |lon, lat| {
        300.0 + 200.0 * lon.sin() * (2.0 * lat).cos()
    });
    let high = ascii_grid(
        dir,
        "high.asc",
        (9.6, 44.3, 0.005),
        (200, 160),
        |lon, lat| {
            if (lon - HOLE[0]).hypot(lat - HOLE[1]) < HOLE[2] {
                f64::NAN
            } else {
                800.0 + 150.0 * (20.0 * lon).sin() * (15.0 * lat).cos()
            }
        },
    );
    (low, high)
}

/// Whether the rectangle `[west, south, east, north]` overlaps [`HIGH`].
fn meets_high(r: [f64; 4]) -> bool {
    r[0] < HIGH[2] && HIGH[0] < r[2] && r[1] < HIGH[3] && HIGH[1] < r[3]
}

/// Whether the edge from `a` to `b` (a meridian or a parallel) runs partly inside the
/// input's extent and partly outside it: its samples come from both rasters.
fn crosses_the_seam(a: [f64; 2], b: [f64; 2]) -> bool {
    let inside =
        |p: [f64; 2]| (HIGH[0]..=HIGH[2]).contains(&p[0]) && (HIGH[1]..=HIGH[3]).contains(&p[1]);
    let steps = 64;
    let points: Vec<bool> = (0..=steps)
        .map(|k| {
            let t = k as f64 / steps as f64;
            inside([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])])
        })
        .collect();
    points.iter().any(|&p| p) && points.iter().any(|&p| !p)
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_base_fills_the_pyramid_around_the_input_within_the_bound_and_stitched() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let run = |out: &str, threads: &str| {
        let o = dir.run(&[
            "tiles",
            &high,
            "--base",
            &low,
            "-o",
            out,
            "--vertical-datum",
            "ellipsoid",
            "--normals",
            "--quality",
            "0.1",
            "--threads",
            threads,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    run("one", "1");
    run("two", "2");
    let (one, two) = (all_files(&dir.path("one")), all_files(&dir.path("two")));
    assert!(one == two, "1 and 2 threads wrote different bytes");

    let tiles = decode_pyramid(&dir.path("one"));
    let (layer, bounds) = layer_json(&dir.path("one"));
    // The pyramid's extent is both rasters'.
    assert_eq!(bounds, vec![5.0, 40.0, 15.0, 48.0]);
    // `available` lists exactly the tiles written.
    let mut listed = BTreeSet::new();
    for (z, rects) in layer["available"].as_array().unwrap().iter().enumerate() {
        for r in rects.as_array().unwrap() {
            let c = |k: &str| r[k].as_u64().unwrap() as u32;
            for x in c("startX")..=c("endX") {
                for y in c("startY")..=c("endY") {
                    assert!(listed.insert((z as u32, x, y)));
                }
            }
        }
    }
    assert_eq!(listed, tiles.keys().copied().collect::<BTreeSet<_>>());

    // Down to the base's own level, every tile either raster reaches; finer, only the
    // input's.
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    assert!(max_zoom > BASE_LEVEL + 1, "{max_zoom}");
    let rect = |&(z, x, y): &(u32, u32, u32)| Tiling::Geographic.rectangle(z, x, y);
    for key in tiles.keys() {
        assert!(key.0 <= BASE_LEVEL || meets_high(rect(key)), "{key:?}");
    }
    let base_only = |z: u32| {
        tiles
            .keys()
            .filter(|k| k.0 == z && !meets_high(rect(k)))
            .count()
    };
    assert!(base_only(BASE_LEVEL) > 0 && base_only(BASE_LEVEL + 1) == 0);

    // Same-level neighbours agree on their edges, those across the seam included.
    for (&key, t) in &tiles {
        check_tile(key, t);
    }
    assert!(check_shared_edges(&tiles) > 0);
    let mut seams = BTreeSet::new();
    for (&(z, x, y), t) in &tiles {
        let r = rect(&(z, x, y));
        for (dx, dy, a, b) in [
            (1, 0, [r[2], r[1]], [r[2], r[3]]),
            (0, 1, [r[0], r[3]], [r[2], r[3]]),
        ] {
            let Some(other) = tiles.get(&(z, x + dx, y + dy)) else {
                continue;
            };
            if crosses_the_seam(a, b) {
                let pair: BTreeMap<(u32, u32, u32), Tile> =
                    [((z, x, y), t.clone()), ((z, x + dx, y + dy), other.clone())].into();
                assert!(check_shared_edges(&pair) > 2, "{z}/{x}/{y}");
                seams.insert(z);
            }
        }
    }
    assert!(
        seams.contains(&BASE_LEVEL) && seams.contains(&max_zoom),
        "seams tested at levels {seams:?}"
    );

    // From the base's own level down, every sample is sampled from the rasters (coarser
    // levels are filtered from it): within the bound of GDAL's warp of the base, then the
    // input over it, at every lattice point.
    let checked = check_against_gdal(&dir, &tiles, &[&low, &high], Tiling::Geographic, BASE_LEVEL);
    assert!(checked > 10, "{checked}");
}

/// Asserts every tile of `tiles` from level `from` down is within `0.1 x` its level's
/// error of GDAL's warp of `rasters` (in priority order, the last on top) at every
/// lattice point away from the input's hole's rim; returns how many tiles it checked.
fn check_against_gdal(
    dir: &Dir,
    tiles: &BTreeMap<(u32, u32, u32), Tile>,
    rasters: &[&str],
    tiling: Tiling,
    from: u32,
) -> usize {
    let mut checked = 0;
    for (&(z, x, y), t) in tiles.range((from, 0, 0)..) {
        let bound = 0.1 * tiling.level_error(z);
        let mut samples = stacked_gdal_samples(dir, rasters, tiling, t.cells(), z, x, y);
        skip_the_rim(&mut samples, tiling, z, x, y);
        let e = max_error(t, &samples);
        assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
        checked += 1;
    }
    checked
}

/// Sets the samples of tile `z/x/y`'s lattice near the input's hole's rim to NaN (see
/// [`near_the_rim`]).
fn skip_the_rim(samples: &mut [Vec<f64>], tiling: Tiling, z: u32, x: u32, y: u32) {
    let [west, south, east, north] = tiling.rectangle(z, x, y);
    let n = samples.len() - 1;
    for (j, row) in samples.iter_mut().enumerate() {
        // Web Mercator rows are even in latitude inside a tile, as the test lattice is.
        let lat = south + (north - south) * j as f64 / n as f64;
        for (i, s) in row.iter_mut().enumerate() {
            if near_the_rim(west + (east - west) * i as f64 / n as f64, lat) {
                *s = f64::NAN;
            }
        }
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn each_raster_is_shifted_by_its_own_vertical_datum() {
    // The base declares EGM96 heights (about 47 m above the ellipsoid here), the input no
    // vertical CRS: the base's samples are shifted, the input's are not.
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let declared = dir.path("low_egm96.tif").to_string_lossy().into_owned();
    let status = Command::new("gdal_translate")
        .args(["-q", "-a_srs", "EPSG:4326+5773", &low, &declared])
        .status()
        .expect("gdal_translate runs");
    assert!(status.success());
    let o = dir.run(&[
        "tiles",
        &high,
        "--base",
        &declared,
        "-o",
        "p",
        "--quality",
        "0.005",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("low_egm96.tif: heights above egm96"), "{err}");
    assert!(err.contains("high.asc: no vertical CRS"), "{err}");
    let tiles = decode_pyramid(&dir.path("p"));
    let (mut base_samples, mut input_samples) = (0, 0);
    for (&(z, x, y), t) in tiles.range((BASE_LEVEL, 0, 0)..) {
        let bound = 0.005 * Tiling::Geographic.level_error(z);
        let cells = t.cells();
        let mut samples =
            stacked_gdal_samples(&dir, &[&low, &high], Tiling::Geographic, cells, z, x, y);
        let input = stacked_gdal_samples(&dir, &[&high], Tiling::Geographic, cells, z, x, y);
        let n = egm96_undulations(cells, z, x, y);
        for ((row, input_row), n_row) in samples.iter_mut().zip(&input).zip(&n) {
            for ((s, i), n) in row.iter_mut().zip(input_row).zip(n_row) {
                if i.is_nan() && s.is_finite() {
                    assert!(*n > 2.0 * bound, "{z}/{x}/{y}: the geoid must matter");
                    *s += n;
                    base_samples += 1;
                } else if i.is_finite() {
                    input_samples += 1;
                }
            }
        }
        skip_the_rim(&mut samples, Tiling::Geographic, z, x, y);
        let e = max_error(t, &samples);
        assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
    }
    assert!(base_samples > 0 && input_samples > 0);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_base_works_in_web_mercator_and_as_3d_tiles() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec!["tiles", &high, "--base", &low, "-o", out, "-q"];
        args.extend_from_slice(&["--vertical-datum", "ellipsoid"]);
        args.extend_from_slice(extra);
        let o = dir.run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    run("mercator", &["--tiling", "mercator", "--quality", "0.1"]);
    let tiles = decode_pyramid(&dir.path("mercator"));
    let (layer, _) = layer_json(&dir.path("mercator"));
    assert_eq!(layer["projection"], "EPSG:3857");
    let max_zoom = layer["maxzoom"].as_u64().unwrap() as u32;
    for (&key, t) in &tiles {
        check_tile(key, t);
    }
    assert!(check_shared_edges(&tiles) > 0);
    let checked = check_against_gdal(&dir, &tiles, &[&low, &high], Tiling::Mercator, max_zoom);
    assert!(checked > 0);

    // 3D Tiles: one GLB for each tile the quantized-mesh pyramid writes.
    run("qm", &[]);
    run("3d", &["--format", "3dtiles"]);
    let count = |root: &str, extension: &str| {
        all_files(&dir.path(root))
            .keys()
            .filter(|p| p.extension().is_some_and(|e| e == extension))
            .count()
    };
    assert!(dir.path("3d").join("tileset.json").exists());
    assert_eq!(count("3d", "glb"), count("qm", "terrain"));
    assert!(count("qm", "terrain") > 20);
}

#[test]
fn a_tile_over_a_base_does_not_depend_on_the_zoom_range_or_the_threads() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec!["tiles", &high, "--base", &low, "-o", out, "-q"];
        args.extend_from_slice(&["--vertical-datum", "ellipsoid", "--normals"]);
        args.extend_from_slice(extra);
        let o = dir.run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        all_files(&dir.path(out))
            .into_iter()
            .filter(|(p, _)| p.extension().is_some_and(|e| e == "terrain"))
            .collect::<BTreeMap<_, _>>()
    };
    let all = run("all", &["--threads", "2"]);
    let some = run(
        "some",
        &["--min-zoom", "3", "--max-zoom", "6", "--threads", "1"],
    );
    assert!(some.len() > 5 && some.len() < all.len());
    for (path, bytes) in &some {
        assert!(all.get(path) == Some(bytes), "{path:?} differs");
    }
}

#[test]
fn the_finest_level_is_the_inputs_own_on_the_bases_lattice() {
    // The 0.05° base takes tiles of 151 cells (level 5: 0.037°, where 217 cells give
    // 0.026°). A 0.0009° input is first sampled at least as finely at level 10 with 217
    // cells (0.00081°) but at level 11 with 151 (0.00058°; level 10 is 0.00116°).
    let dir = Dir::new();
    let (low, _) = inputs(&dir);
    let fine = ascii_grid(
        &dir,
        "fine.asc",
        (9.6, 44.3, 0.0009),
        (60, 50),
        |lon, lat| 500.0 + 40.0 * (300.0 * lon).sin() * (200.0 * lat).cos(),
    );
    let o = dir.run(&[
        "tiles", &fine, "--base", &low, "-o", "p", "--report", "r.json", "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path("r.json")).unwrap()).unwrap();
    assert_eq!(report["lattice_cells"], 151);
    assert_eq!(report["max_zoom"], 11);
    let tiles = decode_pyramid(&dir.path("p"));
    assert_eq!(tiles.values().next().unwrap().cells(), 151);
    assert!(tiles.keys().any(|k| k.0 == 11));
}

#[test]
fn a_base_that_is_missing_not_a_raster_or_not_placed_is_refused_naming_it() {
    let dir = Dir::new();
    let (_, high) = inputs(&dir);
    dir.write("notes.txt", "not a raster\n");
    let plain = ascii_grid(&dir, "plain.asc", (5.0, 40.0, 0.05), (20, 20), |_, _| 1.0);
    std::fs::remove_file(dir.path("plain.prj")).unwrap();
    for (base, why) in [
        ("missing.tif", "missing.tif"),
        ("notes.txt", "notes.txt"),
        (plain.as_str(), "CRS"),
    ] {
        let o = dir.run(&["tiles", &high, "--base", base, "-o", "out", "-q"]);
        assert_fails_naming(&o, &["--base", base, why]);
        assert!(!dir.path("out").exists(), "{base}");
    }
}

#[test]
fn an_option_a_base_does_not_work_with_is_refused_by_name() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let o = dir.run(&[
        "tiles",
        &high,
        "--base",
        &low,
        "-o",
        "out",
        "-q",
        "--water",
        "sea-level",
    ]);
    assert_fails_naming(&o, &["--water sea-level", "--base"]);
    assert!(!dir.path("out").join("layer.json").exists());
}

/// The level of a tile file `z/x/y.terrain`.
fn level_of(path: &std::path::Path) -> u32 {
    let first = path.iter().next().and_then(|c| c.to_str()).unwrap();
    first.parse().unwrap()
}

#[test]
fn shards_over_a_base_are_the_one_process_pyramid() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let extra = ["--base", low.as_str(), "--vertical-datum", "ellipsoid"];
    check_shards(&dir, &high, &extra, &[2, 5]);
}

#[test]
fn an_update_over_a_base_rebuilds_what_either_raster_changed() {
    let dir = Dir::new();
    let (low, high) = inputs(&dir);
    let args = |out: &'static str, update: bool| {
        let mut a = vec![
            "tiles",
            high.as_str(),
            "--base",
            low.as_str(),
            "-o",
            out,
            "-q",
        ];
        a.extend_from_slice(&["--vertical-datum", "ellipsoid"]);
        if update {
            a.push("--update");
        }
        a
    };
    run_ok(&dir, &args("p", false));
    // The base raised by 50 m west of 6.5°E, far from the input; then the input raised
    // by 30 m in its north-east corner, as rasters are re-surveyed in place.
    type Rewrite<'a> = Box<dyn Fn() -> String + 'a>;
    let rewrites: [(&str, Rewrite); 2] = [
        (
            "base",
            Box::new(|| {
                ascii_grid(
                    &dir,
                    "low.asc",
                    (5.0, 40.0, 0.05),
                    (200, 160),
                    |lon, lat| {
                        let rise = if lon < 6.5 { 50.0 } else { 0.0 };
                        300.0 + rise + 200.0 * lon.sin() * (2.0 * lat).cos()
                    },
                )
            }),
        ),
        (
            "input",
            Box::new(|| {
                ascii_grid(
                    &dir,
                    "high.asc",
                    (9.6, 44.3, 0.005),
                    (200, 160),
                    |lon, lat| {
                        if (lon - HOLE[0]).hypot(lat - HOLE[1]) < HOLE[2] {
                            f64::NAN
                        } else {
                            let rise = if lon > 10.5 && lat > 45.0 { 30.0 } else { 0.0 };
                            800.0 + rise + 150.0 * (20.0 * lon).sin() * (15.0 * lat).cos()
                        }
                    },
                )
            }),
        ),
    ];
    for (what, rewrite) in rewrites {
        let old = identities(&dir.path("p"));
        rewrite();
        run_ok(&dir, &args("p", true));
        let _ = std::fs::remove_dir_all(dir.path("fresh"));
        run_ok(&dir, &args("fresh", false));
        let (updated, fresh) = (
            pyramid_files(&dir.path("p")),
            pyramid_files(&dir.path("fresh")),
        );
        let differ = differences(&fresh, &updated);
        assert!(
            differ.is_empty(),
            "{what}: the update differs in {differ:?}"
        );
        let new = identities(&dir.path("p"));
        let rewritten: Vec<u32> = new
            .iter()
            .filter(|(p, id)| old.get(*p) != Some(id))
            .map(|(p, _)| level_of(p))
            .collect();
        assert!(!rewritten.is_empty(), "{what}: the change rewrote no tile");
        assert!(rewritten.len() < new.len(), "{what}: every tile rewritten");
        if what == "base" {
            // Far from the input: the levels finer than the base's own read the input and
            // the base only near it.
            assert!(
                rewritten.iter().all(|&z| z <= BASE_LEVEL),
                "{what}: rewrote tiles at levels {rewritten:?}"
            );
        }
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn several_bases_stacked_in_a_vrt_keep_its_priority_the_bound_and_shared_edges() {
    let dir = Dir::new();
    let (_, high) = inputs(&dir);
    // Two bases overlapping over 9..10°E, each of its own shape; the VRT lists the east
    // one last, so it is read where both have data (gdalbuildvrt's order).
    let west = ascii_grid(
        &dir,
        "west.asc",
        (5.0, 40.0, 0.05),
        (100, 160),
        |lon, lat| 300.0 + 200.0 * lon.sin() * (2.0 * lat).cos(),
    );
    let east = ascii_grid(
        &dir,
        "east.asc",
        (9.0, 41.0, 0.05),
        (120, 120),
        |lon, lat| 900.0 + 300.0 * (3.0 * lon).cos() * lat.sin(),
    );
    let vrt = dir.path("bases.vrt").to_string_lossy().into_owned();
    let status = Command::new("gdalbuildvrt")
        .args(["-q", &vrt, &west, &east])
        .status()
        .unwrap();
    assert!(status.success());
    let o = dir.run(&[
        "tiles",
        &high,
        "--base",
        &vrt,
        "-o",
        "p",
        "--vertical-datum",
        "ellipsoid",
        "--quality",
        "0.1",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let tiles = decode_pyramid(&dir.path("p"));
    for (&key, t) in &tiles {
        check_tile(key, t);
    }
    assert!(check_shared_edges(&tiles) > 0);
    // Every lattice point from the bases' own level down is within the bound of GDAL's
    // warp of the VRT, then the input over it.
    let checked = check_against_gdal(&dir, &tiles, &[&vrt, &high], Tiling::Geographic, BASE_LEVEL);
    assert!(checked > 10, "{checked}");
    // Where both bases have data, away from their edges and the input, the vertices of
    // the base's own level carry the east base's heights, not the west one's.
    let z = BASE_LEVEL;
    let bound = 0.1 * Tiling::Geographic.level_error(z);
    let mut over_both = 0;
    for (&(tz, x, y), t) in tiles.range((z, 0, 0)..(z + 1, 0, 0)) {
        let [w, s, e, n] = Tiling::Geographic.rectangle(tz, x, y);
        for k in 0..t.h.len() {
            let lon = w + (e - w) * t.u[k] as f64 / 32767.0;
            let lat = s + (n - s) * t.v[k] as f64 / 32767.0;
            if !((9.2..9.8).contains(&lon) && (41.2..46.8).contains(&lat)) {
                continue;
            }
            let east = 900.0 + 300.0 * (3.0 * lon).cos() * lat.sin();
            let west = 300.0 + 200.0 * lon.sin() * (2.0 * lat).cos();
            assert!(
                (t.h[k] - east).abs() <= bound + 1.0 && (t.h[k] - west).abs() > bound + 1.0,
                "{tz}/{x}/{y} at {lon}, {lat}: {} (east {east}, west {west})",
                t.h[k]
            );
            over_both += 1;
        }
    }
    assert!(over_both > 0, "no vertex where both bases have data");
}
