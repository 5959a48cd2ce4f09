//! A real client: CesiumJS in headless Chromium loads a pyramid from `tinsmith serve`
//! (`CesiumTerrainProvider.fromUrl`, `sampleTerrainMostDetailed`), from the directory
//! `tinsmith tiles` wrote and from the same pyramid in an MBTiles file (served by a second
//! server, so the page loads it across origins, through CORS), and a pyramid of EGM96
//! heights turned into ellipsoidal ones (`--vertical-datum egm96`), and a Web Mercator
//! pyramid (`--tiling mercator`). A missing CesiumJS or
//! Chromium install, or a Chromium that cannot start, fails. `#[ignore]`d so that `cargo
//! test` passes with only GDAL installed; `make test` runs it (`--include-ignored`).

use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::tiles::{
    ascii_grid, decode_pyramid, egm96_undulations, gdal_samples, tiled_gdal_samples, Tiling,
};
use crate::util::{fixture, serve, stderr, Dir};

/// CesiumJS's samples of the pyramid at `terrain` (a URL; `tileset.json` for 3D Tiles) at
/// the points of `points_file`, by `tests/oracle/cesium_sample.cjs` on the page at `base`
/// (with `water_tile` Z/X/Y, that tile's water mask too): its JSON result, asserting it
/// ran with no console error and no failed request.
/// Cells a side of the lattice of the quantized-mesh pyramid in `dir`, from its decoded
/// vertices.
fn lattice_cells(dir: &Path) -> i64 {
    decode_pyramid(dir).values().next().expect("a tile").cells()
}

fn cesium_sample(base: &str, terrain: &str, points_file: &Path, water_tile: Option<&str>) -> Value {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut command = Command::new("node");
    command
        .arg(repo.join("tests/oracle/cesium_sample.cjs"))
        .arg(format!("{base}index.html"))
        .arg(terrain)
        .arg(points_file);
    if let Some(tile) = water_tile {
        command.arg(tile);
    }
    let out = command.output().expect("node runs");
    assert!(
        out.status.success(),
        "{terrain}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let result: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(result["consoleErrors"], serde_json::json!([]), "{result}");
    assert_eq!(result["failedRequests"], serde_json::json!([]), "{result}");
    result
}

/// `DIR/site/`: CesiumJS (linked from `.tools`) and a page that loads it, beside the
/// pyramids a test writes there. Fails when CesiumJS or Chromium is missing.
fn cesium_page(dir: &Dir) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cesium = repo.join(".tools/node_modules/cesium/Build/Cesium");
    assert!(
        cesium.join("Cesium.js").exists() && Path::new("/usr/bin/chromium").exists(),
        "CesiumJS or Chromium is missing: run `make oracles`"
    );
    std::os::unix::fs::symlink(&cesium, dir.path("site/cesium")).unwrap();
    dir.write(
        "site/index.html",
        "<!doctype html><html><head><link rel=\"icon\" href=\"data:,\"><script>window.CESIUM_BASE_URL = '/cesium/';</script>\
         <script src=\"/cesium/Cesium.js\"></script></head><body></body></html>\n",
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn cesiumjs_samples_the_served_pyramid_within_the_bound() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    let o = dir.run(&["tiles", &input, "-o", "site/terrain", "--normals"]);
    assert!(o.status.success(), "{}", stderr(&o));
    cesium_page(&dir);
    let layer: Value =
        serde_json::from_slice(&std::fs::read(dir.path("site/terrain/layer.json")).unwrap())
            .unwrap();
    let z = layer["maxzoom"].as_u64().unwrap() as u32;
    let rect = &layer["available"][z as usize][0];
    let (x, y) = (
        rect["startX"].as_u64().unwrap() as u32,
        rect["startY"].as_u64().unwrap() as u32,
    );

    // Points on the finest tile's sample lattice, away from its edges, where the tile's
    // source samples are known (GDAL's warp of the same lattice).
    let cells = lattice_cells(&dir.path("site/terrain"));
    let samples = gdal_samples(&dir, &input, cells, z, x, y);
    let size = 180.0 / (1u64 << z) as f64;
    let d = size / cells as f64;
    let (west, south) = (-180.0 + x as f64 * size, -90.0 + y as f64 * size);
    let undulations = egm96_undulations(cells, z, x, y);
    let mut points = Vec::new();
    let mut expected = Vec::new();
    let mut above_geoid = Vec::new();
    let inner = 3..cells as usize - 2;
    let valid: Vec<(usize, usize)> = inner
        .clone()
        .flat_map(|j| inner.clone().map(move |i| (i, j)))
        .filter(|&(i, j)| samples[j][i].is_finite())
        .collect();
    for k in 0..6 {
        let Some(&(i, j)) = valid.get(k * valid.len() / 6 + valid.len() / 12) else {
            continue;
        };
        points.push([west + i as f64 * d, south + j as f64 * d]);
        expected.push(samples[j][i]);
        above_geoid.push(samples[j][i] + undulations[j][i]);
    }
    assert!(points.len() >= 3, "too few sample points with data");
    let points_file = dir.write("points.json", &serde_json::to_string(&points).unwrap());

    // The same pyramid written as one MBTiles file by `tiles -o`.
    let o = dir.run(&["tiles", &input, "-o", "terrain.mbtiles", "--normals", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));

    // The DEM's heights taken as EGM96 heights: CesiumJS then samples H + N.
    let o = dir.run(&[
        "tiles",
        &input,
        "-o",
        "site/geoid",
        "--normals",
        "--vertical-datum",
        "egm96",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));

    let (_server, base) = serve(&dir, &["site"]);
    let (_mbtiles_server, mbtiles_base) = serve(&dir, &["terrain.mbtiles"]);
    let bound = 77_067.34 / (1u64 << z) as f64;
    let mut heights = Vec::new();
    for (terrain, expected) in [
        (format!("{base}terrain/"), &expected),
        (mbtiles_base, &expected),
        (format!("{base}geoid/"), &above_geoid),
    ] {
        let result = cesium_sample(&base, &terrain, &points_file, None);
        for (k, want) in expected.iter().enumerate() {
            assert_eq!(result["levels"][k].as_u64(), Some(z as u64), "{result}");
            let got = result["heights"][k]
                .as_f64()
                .unwrap_or_else(|| panic!("{terrain}: point {k} has no height: {result}"));
            assert!(
                (got - want).abs() <= bound + 1e-3,
                "{terrain}: point {k}: CesiumJS {got}, DEM {want}, bound {bound}"
            );
        }
        heights.push(result["heights"].clone());
    }
    // The same tiles, so the same heights, to the bit.
    assert_eq!(heights[0], heights[1]);
    assert_ne!(heights[0], heights[2]);
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn cesiumjs_receives_the_water_masks_as_quantized_mesh_and_as_3d_tiles() {
    let dir = Dir::new();
    // Land west of 10.6°E, nodata sea east of it.
    let dem = ascii_grid(
        &dir,
        "coast.asc",
        (10.0, 45.0, 0.01),
        (100, 100),
        |lon, _| {
            if lon > 10.6 {
                f64::NAN
            } else {
                50.0 + 100.0 * (lon - 10.0)
            }
        },
    );
    for (out, format) in [("site/terrain", "quantized-mesh"), ("site/glb", "3dtiles")] {
        let o = dir.run(&[
            "tiles",
            &dem,
            "-o",
            out,
            "--water",
            "sea-level",
            "--format",
            format,
            "-q",
        ]);
        assert!(o.status.success(), "{format}: {}", stderr(&o));
    }
    cesium_page(&dir);
    let tiles = decode_pyramid(&dir.path("site/terrain"));
    let (&(z, x, y), finest) = tiles.iter().next_back().expect("tiles");
    let ours = finest.water_mask.clone().expect("a water mask");
    assert_eq!(ours.len(), 65536, "a tile with land and water");
    assert!(ours.contains(&0) && ours.contains(&255));
    // A level-0 tile away from the DEM: beyond the DEM is its nodata sea, so all water,
    // a mask of one byte (in 3D Tiles, a 1 x 1 image).
    let root = tiles[&(0, 0, 0)].water_mask.clone().expect("a water mask");
    assert_eq!(root, vec![255]);
    let points_file = dir.write("points.json", "[[10.3, 45.5]]");
    let (_server, base) = serve(&dir, &["site"]);
    for (terrain, tile, want) in [
        ("terrain/", (z, x, y), Some(&ours)),
        ("glb/tileset.json", (z, x, y), Some(&ours)),
        ("terrain/", (0, 0, 0), Some(&root)),
        ("glb/tileset.json", (0, 0, 0), Some(&root)),
    ] {
        let water = format!("{}/{}/{}", tile.0, tile.1, tile.2);
        let result = cesium_sample(
            &base,
            &format!("{base}{terrain}"),
            &points_file,
            Some(&water),
        );
        assert_eq!(result["hasWaterMask"], true);
        let theirs: Option<Vec<u64>> = result["waterMask"]
            .as_array()
            .map(|a| a.iter().map(|v| v.as_u64().unwrap()).collect());
        assert!(
            theirs.as_ref() == want,
            "{terrain} {tile:?}: CesiumJS decoded another water mask"
        );
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn cesiumjs_samples_the_3dtiles_pyramid_as_the_quantized_mesh_one() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    for (out, format) in [("site/qm", "quantized-mesh"), ("site/t3d", "3dtiles")] {
        let o = dir.run(&[
            "tiles",
            &input,
            "-o",
            out,
            "--normals",
            "--format",
            format,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    cesium_page(&dir);
    let layer: Value =
        serde_json::from_slice(&std::fs::read(dir.path("site/qm/layer.json")).unwrap()).unwrap();
    let z = layer["maxzoom"].as_u64().unwrap() as u32;
    let rect = &layer["available"][z as usize][0];
    let (x, y) = (
        rect["startX"].as_u64().unwrap() as u32,
        rect["startY"].as_u64().unwrap() as u32,
    );
    // Lattice points of the finest tile, away from its edges, with GDAL's samples there.
    let cells = lattice_cells(&dir.path("site/qm"));
    let samples = gdal_samples(&dir, &input, cells, z, x, y);
    let size = 180.0 / (1u64 << z) as f64;
    let d = size / cells as f64;
    let (west, south) = (-180.0 + x as f64 * size, -90.0 + y as f64 * size);
    let inner = 3..cells as usize - 2;
    let valid: Vec<(usize, usize)> = inner
        .clone()
        .flat_map(|j| inner.clone().map(move |i| (i, j)))
        .filter(|&(i, j)| samples[j][i].is_finite())
        .collect();
    let picks: Vec<(usize, usize)> = (0..8)
        .filter_map(|k| valid.get(k * valid.len() / 8 + valid.len() / 16).copied())
        .collect();
    assert!(picks.len() >= 3, "too few sample points with data");
    let points: Vec<[f64; 2]> = picks
        .iter()
        .map(|&(i, j)| [west + i as f64 * d, south + j as f64 * d])
        .collect();
    let points_file = dir.write("points.json", &serde_json::to_string(&points).unwrap());
    let (_server, base) = serve(&dir, &["site"]);
    let bound = 77_067.34 / (1u64 << z) as f64;
    let mut heights = Vec::new();
    for terrain in [format!("{base}qm/"), format!("{base}t3d/tileset.json")] {
        let result = cesium_sample(&base, &terrain, &points_file, None);
        let mut got = Vec::new();
        for (k, &(i, j)) in picks.iter().enumerate() {
            assert_eq!(result["levels"][k].as_u64(), Some(z as u64), "{result}");
            let h = result["heights"][k]
                .as_f64()
                .unwrap_or_else(|| panic!("{terrain}: point {k} has no height: {result}"));
            let want = samples[j][i];
            assert!(
                (h - want).abs() <= bound + 1e-3,
                "{terrain}: point {k}: CesiumJS {h}, DEM {want}, bound {bound}"
            );
            got.push(h);
        }
        heights.push(got);
    }
    // The same tiles: the same heights but for CesiumJS's own handling of each format
    // (float32 positions turned back into longitude, latitude and height for 3D Tiles);
    // about 1 cm apart at most here, where the bound is 2.35 m.
    for (k, (a, b)) in heights[0].iter().zip(&heights[1]).enumerate() {
        assert!(
            (a - b).abs() < 1e-2 * bound,
            "point {k}: quantized-mesh {a}, 3D Tiles {b}"
        );
    }
    eprintln!(
        "quantized-mesh {:?}\n3D Tiles       {:?}",
        heights[0], heights[1]
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn cesiumjs_samples_a_web_mercator_pyramid_within_the_bound() {
    let dir = Dir::new();
    // At 49°N, where a Web Mercator tile's rows (even in latitude) are far from even in
    // Web Mercator y at coarse levels.
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let o = dir.run(&[
        "tiles",
        &input,
        "-o",
        "site/terrain",
        "--normals",
        "--tiling",
        "mercator",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    cesium_page(&dir);
    let layer: Value =
        serde_json::from_slice(&std::fs::read(dir.path("site/terrain/layer.json")).unwrap())
            .unwrap();
    assert_eq!(layer["projection"], "EPSG:3857");
    let z = layer["maxzoom"].as_u64().unwrap() as u32;
    let tiles = decode_pyramid(&dir.path("site/terrain"));
    let finest: Vec<(u32, u32)> = tiles
        .keys()
        .filter(|k| k.0 == z)
        .map(|k| (k.1, k.2))
        .collect();
    assert!(finest.len() > 1);

    // Points on the finest tiles' sample lattices (even in longitude and in latitude
    // across each tile), away from their edges, with GDAL's warp of the same lattice.
    let mut points = Vec::new();
    let mut expected = Vec::new();
    let mut tile_of = Vec::new();
    for &(x, y) in &finest {
        let cells = tiles[&(z, x, y)].cells();
        let samples = tiled_gdal_samples(&dir, &input, Tiling::Mercator, cells, z, x, y);
        let [west, south, east, north] = Tiling::Mercator.rectangle(z, x, y);
        let inner = 3..cells as usize - 2;
        let valid: Vec<(usize, usize)> = inner
            .clone()
            .flat_map(|j| inner.clone().map(move |i| (i, j)))
            .filter(|&(i, j)| samples[j][i].is_finite())
            .collect();
        for k in 0..4 {
            let Some(&(i, j)) = valid.get(k * valid.len() / 4 + valid.len() / 8) else {
                continue;
            };
            let (u, v) = (i as f64 / cells as f64, j as f64 / cells as f64);
            points.push([west + u * (east - west), south + v * (north - south)]);
            expected.push(samples[j][i]);
            tile_of.push((x, y));
        }
    }
    assert!(points.len() >= 6, "too few sample points with data");
    let points_file = dir.write("points.json", &serde_json::to_string(&points).unwrap());
    let (_server, base) = serve(&dir, &["site"]);
    let result = cesium_sample(&base, &format!("{base}terrain/"), &points_file, None);
    assert_eq!(result["tiling"], "mercator", "{result}");
    let bound = Tiling::Mercator.level_error(z);
    for (k, want) in expected.iter().enumerate() {
        assert_eq!(result["levels"][k].as_u64(), Some(z as u64), "{result}");
        // CesiumJS's tile of the point is the one whose lattice it was taken from, with
        // the same rectangle.
        let tile: Vec<f64> = result["tiles"][k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let (x, y) = tile_of[k];
        assert_eq!(
            (tile[0], tile[1]),
            (x as f64, ((1u64 << z) - 1 - y as u64) as f64),
            "point {k}"
        );
        let ours = Tiling::Mercator.rectangle(z, x, y);
        for (a, b) in ours.iter().zip(&tile[2..]) {
            assert!(
                (a - b).abs() < 1e-9,
                "point {k}: rectangle {ours:?} vs {tile:?}"
            );
        }
        let got = result["heights"][k]
            .as_f64()
            .unwrap_or_else(|| panic!("point {k} has no height: {result}"));
        assert!(
            (got - want).abs() <= bound + 1e-3,
            "point {k}: CesiumJS {got}, DEM {want}, bound {bound}"
        );
    }
}
