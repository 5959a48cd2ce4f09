//! `tinsmith tiles --format 3dtiles`: every GLB of a small pyramid read by this test's own
//! GLB reader and ECEF inverse (no tinsmith code), compared with the quantized-mesh
//! pyramid of the same input (decoded by the independent HERE decoder): the same
//! vertices, triangles and edges, heights within float32's rounding; the finest level
//! against GDAL's own warp of each tile's lattice; neighbours' shared edges at the same
//! places; the Khronos glTF validator on every GLB; the same bytes for 1 and 2 threads.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::shards::{check_shards, differences, identities, patched, pyramid_files, run_ok};
use crate::tiles::{all_files, decode_pyramid, gdal_samples, max_error, Tile};
use crate::util::{assert_fails_naming, fixture, stderr, Dir};

const E0: f64 = 77_067.34;
const A: f64 = 6_378_137.0;
const B: f64 = 6_356_752.314_245_179;

/// One GLB as this test reads it: ECEF vertices, triangles, the four edge lists
/// (left, bottom, right, top) and whether it has normals.
struct Glb {
    ecef: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    edges: [Vec<usize>; 4],
    normals: bool,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Reads a GLB written for `Cesium3DTilesTerrainProvider`: `nodes[0].matrix` a
/// translation (glTF Y-up), float32 positions, `CESIUM_tile_edges`.
fn read_glb(bytes: &[u8]) -> Glb {
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32_at(bytes, 4), 2);
    assert_eq!(u32_at(bytes, 8) as usize, bytes.len());
    let json_length = u32_at(bytes, 12) as usize;
    let doc: Value = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    let bin = &bytes[20 + json_length + 8..];
    let matrix: Vec<f64> = doc["nodes"][0]["matrix"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (k, want) in [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .enumerate()
    {
        assert_eq!(matrix[k], *want, "the matrix is a translation");
    }
    let accessor = |index: &Value| -> (usize, usize, u64) {
        let a = &doc["accessors"][index.as_u64().unwrap() as usize];
        let view = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let offset =
            view["byteOffset"].as_u64().unwrap_or(0) + a["byteOffset"].as_u64().unwrap_or(0);
        (
            offset as usize,
            a["count"].as_u64().unwrap() as usize,
            a["componentType"].as_u64().unwrap(),
        )
    };
    let indices = |index: &Value| -> Vec<usize> {
        let (offset, count, component) = accessor(index);
        (0..count)
            .map(|k| match component {
                5123 => {
                    u16::from_le_bytes(bin[offset + 2 * k..offset + 2 * k + 2].try_into().unwrap())
                        as usize
                }
                5125 => u32_at(bin, offset + 4 * k) as usize,
                other => panic!("index component type {other}"),
            })
            .collect()
    };
    let primitive = &doc["meshes"][0]["primitives"][0];
    let (offset, count, component) = accessor(&primitive["attributes"]["POSITION"]);
    assert_eq!(component, 5126);
    let f = |k: usize| {
        f64::from(f32::from_le_bytes(
            bin[offset + 4 * k..offset + 4 * k + 4].try_into().unwrap(),
        ))
    };
    // glTF (x, y, z) is ECEF (x, -z, y): Cesium's Y_UP_TO_Z_UP after the node matrix.
    let ecef = (0..count)
        .map(|i| {
            let (x, y, z) = (
                matrix[12] + f(3 * i),
                matrix[13] + f(3 * i + 1),
                matrix[14] + f(3 * i + 2),
            );
            [x, -z, y]
        })
        .collect();
    let flat = indices(&primitive["indices"]);
    let edges = &primitive["extensions"]["CESIUM_tile_edges"];
    Glb {
        ecef,
        triangles: flat.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        edges: ["left", "bottom", "right", "top"].map(|side| indices(&edges[side])),
        normals: primitive["attributes"]["NORMAL"].is_u64(),
    }
}

/// WGS84 ECEF to longitude, latitude (degrees) and height: a fixed-point iteration on
/// the latitude, to well under a micrometre.
fn geodetic(p: [f64; 3]) -> (f64, f64, f64) {
    let e2 = 1.0 - B * B / (A * A);
    let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
    let lon = p[1].atan2(p[0]);
    let mut lat = p[2].atan2(r * (1.0 - e2));
    let mut h = 0.0;
    for _ in 0..10 {
        let n = A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
        // Stable at the poles too (where r / cos(lat) is not).
        h = r * lat.cos() + p[2] * lat.sin() - A * A / n;
        lat = p[2].atan2(r * (1.0 - e2 * n / (n + h)));
    }
    (lon.to_degrees(), lat.to_degrees(), h)
}

/// Every GLB under `root/tiles/`, by TMS address.
fn glb_files(root: &Path) -> BTreeMap<(u32, u32, u32), PathBuf> {
    let mut out = BTreeMap::new();
    for (path, _) in all_files(root) {
        let parts: Vec<&str> = path.iter().map(|p| p.to_str().unwrap()).collect();
        if parts[0] != "tiles" {
            continue;
        }
        let n = |k: usize| -> u32 { parts[k].trim_end_matches(".glb").parse().unwrap() };
        let (root_tile, z, ix, y) = (n(1), n(2), n(3), n(4));
        out.insert((z, (root_tile << z) + ix, y), root.join(path));
    }
    out
}

/// One subtree file: its JSON and binary chunks.
struct Subtree {
    json: Value,
    bin: Vec<u8>,
}

impl Subtree {
    fn read(bytes: &[u8]) -> Subtree {
        assert_eq!(&bytes[..4], b"subt");
        assert_eq!(u32_at(bytes, 4), 1);
        let json_length = u64::from_le_bytes(bytes[8..16].try_into().unwrap()) as usize;
        let bin_length = u64::from_le_bytes(bytes[16..24].try_into().unwrap()) as usize;
        assert_eq!(24 + json_length + bin_length, bytes.len());
        Subtree {
            json: serde_json::from_slice(&bytes[24..24 + json_length]).unwrap(),
            bin: bytes[24 + json_length..].to_vec(),
        }
    }

    /// The bytes of buffer view `view`.
    fn view(&self, view: &Value) -> &[u8] {
        let v = &self.json["bufferViews"][view.as_u64().unwrap() as usize];
        let offset = v["byteOffset"].as_u64().unwrap() as usize;
        &self.bin[offset..offset + v["byteLength"].as_u64().unwrap() as usize]
    }

    /// Whether bit `bit` of availability `which` is set.
    fn available(&self, which: &Value, bit: usize) -> bool {
        match which["constant"].as_u64() {
            Some(c) => c == 1,
            None => self.view(&which["bitstream"])[bit / 8] & (1 << (bit % 8)) != 0,
        }
    }

    /// How many tiles are available before bit `bit`: the tile's metadata row.
    fn row(&self, bit: usize) -> usize {
        (0..bit)
            .filter(|&b| self.available(&self.json["tileAvailability"], b))
            .count()
    }

    /// `count` float64 values of property `name` at `row`.
    fn values(&self, name: &str, row: usize, count: usize) -> Vec<f64> {
        let table = &self.json["propertyTables"][0];
        let bytes = self.view(&table["properties"][name]["values"]);
        (0..count)
            .map(|k| {
                let at = 8 * (row * count + k);
                f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
            })
            .collect()
    }
}

/// The Morton index of `x`, `y` (x in the even bits).
fn morton(x: u32, y: u32) -> usize {
    (0..16).fold(0, |m, b| {
        m | ((((x >> b) & 1) as usize) << (2 * b)) | ((((y >> b) & 1) as usize) << (2 * b + 1))
    })
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_3dtiles_pyramid_is_the_quantized_mesh_pyramid_in_glb_and_validates() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    for (out, threads) in [("one", "1"), ("two", "2")] {
        let o = dir.run(&[
            "tiles",
            &input,
            "-o",
            out,
            "--format",
            "3dtiles",
            "--normals",
            "--threads",
            threads,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let one = all_files(&dir.path("one"));
    assert!(
        one == all_files(&dir.path("two")),
        "1 and 2 threads wrote different bytes"
    );
    let o = dir.run(&["tiles", &input, "-o", "qm", "--normals", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let qm = decode_pyramid(&dir.path("qm"));
    let glbs = glb_files(&dir.path("one"));
    assert_eq!(
        glbs.keys().collect::<Vec<_>>(),
        qm.keys().collect::<Vec<_>>(),
        "the same tiles"
    );

    let tileset: Value = serde_json::from_slice(&one[Path::new("tileset.json")]).unwrap();
    assert_eq!(tileset["asset"]["version"], "1.1");
    let children = tileset["root"]["children"].as_array().unwrap();
    assert_eq!(children.len(), 2);
    let max_zoom = *glbs.keys().map(|(z, _, _)| z).max().unwrap();
    for child in children {
        let implicit = &child["implicitTiling"];
        assert_eq!(implicit["subdivisionScheme"], "QUADTREE");
        assert_eq!(implicit["availableLevels"], max_zoom + 1);
    }
    assert!(one.keys().any(|p| p.starts_with("subtrees")));

    let mut worst_height = 0.0f64;
    let mut metadata_rows = 0;
    let mut worst_ratio = 0.0f64;
    let mut finest = 0;
    let mut decoded: BTreeMap<(u32, u32, u32), Vec<[f64; 3]>> = BTreeMap::new();
    for (&(z, x, y), path) in &glbs {
        let glb = read_glb(&std::fs::read(path).unwrap());
        let t: &Tile = &qm[&(z, x, y)];
        assert!(glb.normals, "{z}/{x}/{y}: no normals");
        assert_eq!(glb.triangles, t.triangles, "{z}/{x}/{y}: triangles");
        assert_eq!(glb.edges, t.edges, "{z}/{x}/{y}: edges");
        let size = 180.0 / (1u64 << z) as f64;
        let (west, south) = (-180.0 + x as f64 * size, -90.0 + y as f64 * size);
        let bound = E0 / (1u64 << z) as f64;
        let points: Vec<(f64, f64, f64)> = glb.ecef.iter().map(|&p| geodetic(p)).collect();
        let mut heights = Vec::new();
        for (i, &(lon, lat, h)) in points.iter().enumerate() {
            // Into the tile's turn: on the antimeridian -180 and 180 are one longitude.
            let lon = if lon < west - 1.0 {
                lon + 360.0
            } else if lon > west + size + 1.0 {
                lon - 360.0
            } else {
                lon
            };
            let u = (lon - west) / size * 32767.0;
            let v = (lat - south) / size * 32767.0;
            // At a pole any longitude is the same place. A hundredth of a u (a lattice step
            // is 151) is float32's rounding of a level-0 tile's positions, with room.
            let pole = lat.abs() > 90.0 - 1e-6;
            assert!(
                ((u - t.u[i] as f64).abs() < 1e-2 || pole) && (v - t.v[i] as f64).abs() < 1e-2,
                "{z}/{x}/{y} vertex {i}: ({u}, {v}) against ({}, {})",
                t.u[i],
                t.v[i]
            );
            worst_height = worst_height.max((h - t.h[i]).abs());
            worst_ratio = worst_ratio.max((h - t.h[i]).abs() / bound);
            heights.push(h);
        }
        if z == max_zoom {
            // The GLB's own heights against GDAL's warp of the tile's lattice.
            let samples = gdal_samples(&dir, &input, t.cells(), z, x, y);
            let mut mine = t.clone();
            mine.h = heights;
            let e = max_error(&mine, &samples);
            assert!(e <= bound + 1e-3, "{z}/{x}/{y}: error {e} above {bound}");
            finest += 1;
        }
        // The subtree says the tile exists, and its metadata holds the tile.
        let levels = children[0]["implicitTiling"]["subtreeLevels"]
            .as_u64()
            .unwrap() as u32;
        let (root_tile, ix) = (x >> z, x & ((1 << z) - 1));
        let base = z / levels * levels;
        let local = z - base;
        let name = format!(
            "subtrees/{root_tile}/{base}/{}/{}.subtree",
            ix >> local,
            y >> local
        );
        let subtree = Subtree::read(&one[Path::new(&name)]);
        let mask = (1u32 << local) - 1;
        let bit = ((1usize << (2 * local)) - 1) / 3 + morton(ix & mask, y & mask);
        assert!(
            subtree.available(&subtree.json["tileAvailability"], bit),
            "{name}: {z}/{x}/{y}"
        );
        let row = subtree.row(bit);
        let (min, max) = (
            subtree.values("minimumHeight", row, 1)[0],
            subtree.values("maximumHeight", row, 1)[0],
        );
        let sphere = subtree.values("boundingSphere", row, 4);
        let hop = subtree.values("horizonOcclusionPoint", row, 3);
        for (&p, &(_, _, h)) in glb.ecef.iter().zip(&points) {
            assert!(
                h >= min - 1e-3 && h <= max + 1e-3,
                "{z}/{x}/{y}: height {h} outside {min}..{max}"
            );
            let d = ((p[0] - sphere[0]).powi(2)
                + (p[1] - sphere[1]).powi(2)
                + (p[2] - sphere[2]).powi(2))
            .sqrt();
            assert!(
                d <= sphere[3] + 1e-3,
                "{z}/{x}/{y}: vertex outside the bounding sphere"
            );
        }
        // Horizon culling: the point is outside the (scaled) ellipsoid.
        assert!(
            hop.iter().map(|c| c * c).sum::<f64>() >= 1.0,
            "{z}/{x}/{y}: {hop:?}"
        );
        metadata_rows += 1;
        decoded.insert((z, x, y), glb.ecef);
    }
    assert!(finest > 0);
    // No tile more than the GLBs: every subtree's available tiles are GLBs checked above.
    let listed: usize = one
        .iter()
        .filter(|(p, _)| p.starts_with("subtrees"))
        .map(|(_, bytes)| {
            let s = Subtree::read(bytes);
            s.json["tileAvailability"]["availableCount"]
                .as_u64()
                .unwrap() as usize
        })
        .sum();
    assert_eq!(listed, metadata_rows);
    // Float32 positions about the tile's centre move a height by a tiny part of the bound.
    assert!(
        worst_ratio < 1e-4,
        "height off by {worst_height} m, {worst_ratio} of the bound"
    );

    // Neighbours east and west share their edge's vertices (the same lattice points, as
    // the quantized-mesh tiles, checked above): each tile's float32 positions about its
    // own centre put them at the same places to a tiny part of the bound.
    let mut shared = 0;
    let mut worst_gap = 0.0f64;
    let mut worst_gap_ratio = 0.0f64;
    for (&(z, x, y), glb_points) in &decoded {
        // East then north neighbour: this tile's east (north) edge, north to south (west
        // to east), against its west (south) edge, south to north (east to west).
        for ((dx, dy), mine, theirs) in [((1, 0), 2, 0), ((0, 1), 3, 1)] {
            let Some(other) = decoded.get(&(z, x + dx, y + dy)) else {
                continue;
            };
            let mine = &qm[&(z, x, y)].edges[mine];
            let theirs = &qm[&(z, x + dx, y + dy)].edges[theirs];
            assert_eq!(
                mine.len(),
                theirs.len(),
                "{z}/{x}/{y}: shared edge vertex counts"
            );
            let bound = E0 / (1u64 << z) as f64;
            for (&a, &b) in mine.iter().rev().zip(theirs) {
                let (p, q) = (glb_points[a], other[b]);
                let gap =
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                worst_gap = worst_gap.max(gap);
                worst_gap_ratio = worst_gap_ratio.max(gap / bound);
                shared += 1;
            }
        }
    }
    assert!(shared > 0, "no shared edges tested");
    assert!(
        worst_gap_ratio < 1e-4,
        "shared edge vertices {worst_gap} m apart, {worst_gap_ratio} of the bound"
    );
    eprintln!(
        "{} tiles, {shared} shared edge vertices: heights within {worst_height:.2e} m of the \
         quantized-mesh tiles ({worst_ratio:.2e} of the bound), shared edge vertices within \
         {worst_gap:.2e} m ({worst_gap_ratio:.2e} of the bound)",
        glbs.len()
    );

    // The Khronos validator on every GLB.
    let out = Command::new("node")
        .arg(repo.join("tests/oracles/gltf_validate.js"))
        .args(glbs.values())
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reports: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(reports.len(), glbs.len());
    for (report, path) in reports.iter().zip(glbs.values()) {
        assert_eq!(report["issues"]["numErrors"], 0, "{path:?}: {report:#}");
        // Infos only: CESIUM_tile_edges is unknown to it, its accessors no attribute's.
        assert_eq!(report["issues"]["numWarnings"], 0, "{path:?}: {report:#}");
    }
}

#[test]
fn a_3dtiles_pyramid_in_mbtiles_or_without_the_whole_globe_is_refused() {
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    for (extra, names) in [
        (&["-o", "t.mbtiles"][..], &["t.mbtiles", "3dtiles"][..]),
        (
            &["-o", "a", "--min-zoom", "1"][..],
            &["--min-zoom", "3dtiles"][..],
        ),
        (
            &["-o", "b", "--data-only"][..],
            &["--data-only", "3dtiles"][..],
        ),
        (
            &["-o", "c", "--metadata"][..],
            &["--metadata", "3dtiles"][..],
        ),
        (
            &["-o", "e", "--tiling", "mercator"][..],
            &["--tiling mercator", "3dtiles"][..],
        ),
    ] {
        let mut args = vec!["tiles", input.as_str(), "--format", "3dtiles"];
        args.extend_from_slice(extra);
        let o = dir.run(&args);
        assert_fails_naming(&o, names);
        for out in ["t.mbtiles", "a", "b", "c", "e"] {
            assert!(!dir.path(out).exists(), "{out} was written");
        }
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_3dtiles_pyramid_with_water_masks_validates_and_keeps_its_meshes() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Dir::new();
    let input = fixture("etopo5_2deg_i16.tif");
    // Water (255) where the DEM is below 0 m, land (0) elsewhere.
    let mask = dir.path("below0.tif");
    let status = Command::new("gdal_translate")
        .args(["-q", "-ot", "Byte", "-scale", "0", "-1", "0", "255", &input])
        .arg(&mask)
        .status()
        .unwrap();
    assert!(status.success());
    let mask = mask.to_string_lossy().into_owned();
    for (out, water) in [("plain", None), ("water", Some(mask.as_str()))] {
        let mut args = vec![
            "tiles",
            input.as_str(),
            "-o",
            out,
            "--format",
            "3dtiles",
            "-q",
        ];
        if let Some(mask) = water {
            args.extend_from_slice(&["--water", mask]);
        }
        let o = dir.run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let (plain, water) = (glb_files(&dir.path("plain")), glb_files(&dir.path("water")));
    assert_eq!(
        plain.keys().collect::<Vec<_>>(),
        water.keys().collect::<Vec<_>>()
    );
    let mut with_mask = 0;
    for (key, path) in &water {
        let (a, b) = (
            read_glb(&std::fs::read(&plain[key]).unwrap()),
            read_glb(&std::fs::read(path).unwrap()),
        );
        // The same mesh; the mask is added beside it.
        assert_eq!(a.ecef, b.ecef, "{key:?}");
        assert_eq!(a.triangles, b.triangles, "{key:?}");
        let bytes = std::fs::read(path).unwrap();
        with_mask += usize::from(bytes.windows(b"WATERMASK".len()).any(|w| w == b"WATERMASK"));
    }
    assert!(with_mask > 0, "no tile with water");
    let out = Command::new("node")
        .arg(repo.join("tests/oracles/gltf_validate.js"))
        .args(water.values())
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        let report: Value = serde_json::from_str(line).unwrap();
        assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    }
}

#[test]
fn a_3dtiles_pyramid_in_shards_is_the_one_process_pyramid() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    check_shards(&dir, &input, &["--format", "3dtiles", "--normals"], &[2, 7]);
}

#[test]
fn a_3dtiles_update_rebuilds_only_the_tiles_a_change_reaches_and_its_subtrees() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let args = |input: &str, out: &str, update: bool| {
        let mut a = vec![
            "tiles".to_owned(),
            input.to_owned(),
            "-o".into(),
            out.into(),
        ];
        a.extend(["--format", "3dtiles", "-q"].map(String::from));
        if update {
            a.push("--update".into());
        }
        a
    };
    let run = |a: Vec<String>| run_ok(&dir, &a.iter().map(String::as_str).collect::<Vec<_>>());
    let before = patched(&dir, &input, "dem.vrt", [300, 350, 60], 0.0);
    run(args(&before, "p", false));
    let old = identities(&dir.path("p"));
    let after = patched(&dir, &input, "dem.vrt", [300, 350, 60], 40.0);
    run(args(&after, "p", true));
    run(args(&after, "fresh", false));
    let (updated, fresh) = (
        pyramid_files(&dir.path("p")),
        pyramid_files(&dir.path("fresh")),
    );
    let differ = differences(&fresh, &updated);
    assert!(
        differ.is_empty(),
        "the update differs from a fresh build in {differ:?}"
    );
    assert!(fresh.keys().any(|k| k.starts_with("subtrees")));
    let new = identities(&dir.path("p"));
    let rewritten = new.iter().filter(|(p, id)| old.get(*p) != Some(id)).count();
    assert!(
        rewritten > 0 && rewritten * 2 < new.len(),
        "{rewritten} of {}",
        new.len()
    );
    // Records without the tiles' subtree metadata (as a pyramid built before they held
    // it): an update rebuilds those tiles rather than write subtrees without them.
    let records = dir.path("p").join("tinsmith");
    let mut stripped = 0;
    for (name, bytes) in all_files(&records) {
        if name.extension().is_some_and(|e| e == "json") {
            let entry = records.join(name);
            let mut record: Value = serde_json::from_slice(&bytes).unwrap();
            if let Some(tiles) = record.get_mut("tiles").and_then(Value::as_array_mut) {
                for tile in tiles {
                    let fields = tile.as_object_mut().unwrap();
                    stripped += usize::from(fields.remove("bounds").is_some());
                }
                std::fs::write(&entry, serde_json::to_vec(&record).unwrap()).unwrap();
            }
        }
    }
    assert!(stripped > 0);
    run(args(&after, "p", true));
    assert!(
        pyramid_files(&dir.path("p")) == fresh,
        "the update differs from a fresh build"
    );
}
