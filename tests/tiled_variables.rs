//! Several variables over one mesh, tile by tile (`mesh --bands` on a raster larger than
//! `--tile-size`): every band within its bound by the independent verifier, the welded
//! mesh crack-free (shared edges decided once for all bands), the same bytes for any
//! thread count, and the bands' bounds deciding the shared edges' vertices.

use std::collections::HashMap;
use std::path::Path;

use serde_json::Value;

use crate::tiled_mesh::assert_crack_free;
use crate::util::{assert_fails_naming, stderr, stdout, Dir};
use crate::variables::{field, mesh_ok, stack, three_bands, write_band, H, W};

/// Tiles of 16 samples: 3 x 2 tiles on the 40 x 30 fixtures, shared edges at columns 15
/// and 30 and row 15.
const TILE: &str = "16";

/// Vertices of a mesh written with `--pixel-coords` that lie on a shared tile edge.
fn on_shared_edges(mesh: &Path) -> usize {
    let file = tinsmith_formats::read_mesh(mesh).expect("mesh");
    file.vertices
        .iter()
        .filter(|v| {
            let (x, y) = (v[0] as usize, v[1] as usize);
            (x == 15 || x == 30 || y == 15) && x < W && y < H
        })
        .count()
}

fn verify_bands(d: &Dir, mesh: &str, bands: &str, bounds: &str) -> Value {
    let o = d.run(&[
        "verify",
        "multi.tif",
        mesh,
        "--bands",
        bands,
        "--max-error",
        bounds,
        "--pixel-coords",
        "--json",
    ]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("JSON")
}

#[test]
fn tiled_bands_keep_every_bound_and_weld_without_cracks() {
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
            "--tile-size",
            TILE,
            "--pixel-coords",
        ],
    );
    assert_eq!(r["tiles"]["count"], 6, "{r}");
    let vars = r["variables"].as_array().expect("variables in the report");
    for (v, (band, bound)) in vars.iter().zip([(2, 0.5), (3, 0.25)]) {
        assert_eq!(v["band"], band);
        let measured = v["measured_max_error"].as_f64().expect("measured");
        assert!(measured <= bound && measured > 0.0, "{v}");
    }
    let json = verify_bands(&d, "m.ply", "1,2,3", "1,0.5,0.25");
    assert_eq!(
        json["variables"].as_array().map(Vec::len),
        Some(2),
        "{json}"
    );
    assert_eq!(r["triangles_after"], json["height"]["triangles"], "{json}");
    assert_eq!(json["height"]["overlapping_edges"], 0, "{json}");
    assert_eq!(json["height"]["uncovered_samples"], 0, "{json}");
    assert_crack_free(d.path("multi.tif").to_str().unwrap(), &d.path("m.ply"));
    // Each band is measured on its own values: a bound below band 3's error fails it.
    let o = d.run(&[
        "verify",
        "multi.tif",
        "m.ply",
        "--bands",
        "1,2,3",
        "--max-error",
        "1,0.5,0.01",
        "--pixel-coords",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
}

#[test]
fn tiled_identical_bands_give_the_single_band_tiled_mesh() {
    let d = Dir::new();
    write_band(&d, "a.asc", field(0.7));
    write_band(&d, "b.asc", field(0.7));
    stack(&d, "multi.tif", &["a.asc", "b.asc"]);
    let flags = [
        "--vertex-heights",
        "samples",
        "--initial-mesh",
        "rtin",
        "--tile-size",
        TILE,
        "--pixel-coords",
    ];
    let mut args = vec!["-o", "one.ply", "--max-error", "0.5"];
    args.extend_from_slice(&flags);
    let one = mesh_ok(&d, &args);
    let mut args = vec!["-o", "two.ply", "--bands", "1,2", "--max-error", "0.5"];
    args.extend_from_slice(&flags);
    let two = mesh_ok(&d, &args);
    assert_eq!(one["tiles"]["count"], 6);
    assert_eq!(one["triangles_after"], two["triangles_after"]);
    assert_eq!(one["vertices_after"], two["vertices_after"]);
    let (a, b) = (
        tinsmith_formats::read_mesh(&d.path("one.ply")).expect("one"),
        tinsmith_formats::read_mesh(&d.path("two.ply")).expect("two"),
    );
    assert_eq!(a.vertices, b.vertices);
    assert_eq!(a.triangles, b.triangles);
}

#[test]
fn tiled_bands_give_the_same_bytes_for_any_thread_count() {
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
                "--tile-size",
                TILE,
                "--threads",
                threads,
            ],
        );
        bytes.push(std::fs::read(d.path(&name)).unwrap());
    }
    assert_eq!(bytes[0], bytes[1]);
}

#[test]
fn a_tighter_band_keeps_more_vertices_on_shared_edges() {
    let d = Dir::new();
    three_bands(&d);
    let mut counts = Vec::new();
    for bounds in ["1,20", "1,0.5", "1,0.05"] {
        let name = format!("m{bounds}.ply");
        mesh_ok(
            &d,
            &[
                "-o",
                &name,
                "--bands",
                "1,2",
                "--max-error",
                bounds,
                "--tile-size",
                TILE,
                "--pixel-coords",
            ],
        );
        verify_bands(&d, &name, "1,2", bounds);
        assert_crack_free(d.path("multi.tif").to_str().unwrap(), &d.path(&name));
        counts.push(on_shared_edges(&d.path(&name)));
    }
    assert!(counts[0] < counts[1] && counts[1] < counts[2], "{counts:?}");
}

#[test]
fn tiled_nodata_in_one_band_only_shrinks_the_domain_across_tiles() {
    let d = Dir::new();
    write_band(&d, "a.asc", field(0.3));
    // A hole straddling the shared edges at column 15 and row 15.
    write_band(&d, "b.asc", |x, y| {
        if (12..19).contains(&x) && (10..20).contains(&y) {
            f64::NAN
        } else {
            field(1.1)(x, y)
        }
    });
    stack(&d, "multi.tif", &["a.asc", "b.asc"]);
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.ply",
            "--bands",
            "1,2",
            "--max-error",
            "1,0.5",
            "--tile-size",
            TILE,
            "--pixel-coords",
        ],
    );
    // The samples valid in both bands, each counted once across tiles.
    assert_eq!(r["valid_samples"], (W * H - 7 * 10) as u64, "{r}");
    verify_bands(&d, "m.ply", "1,2", "1,0.5");
    let file = tinsmith_formats::read_mesh(&d.path("m.ply")).expect("mesh");
    let inside = |v: &[f64; 3]| (13.0..18.0).contains(&v[0]) && (11.0..19.0).contains(&v[1]);
    assert!(!file.vertices.iter().any(inside));
    // A tiled mesh's picture is drawn from the written file: it checks the mesh on the
    // domain of every band too, not on the height's alone (where the hole is uncovered).
    mesh_ok(
        &d,
        &[
            "-o",
            "p.ply",
            "--bands",
            "1,2",
            "--max-error",
            "1,0.5",
            "--tile-size",
            TILE,
            "--pixel-coords",
            "--preview",
            "p.png",
        ],
    );
    assert!(d.path("p.png").exists(), "the picture is written");
}

#[test]
fn per_tile_files_share_their_edge_vertices_with_every_band() {
    let d = Dir::new();
    three_bands(&d);
    let flags = [
        "--bands",
        "1,2,3",
        "--max-error",
        "1,0.5,0.25",
        "--tile-size",
        TILE,
        "--pixel-coords",
    ];
    let mut args = vec!["--per-tile", "tiles"];
    args.extend_from_slice(&flags);
    mesh_ok(&d, &args);
    let mut args = vec!["-o", "m.ply"];
    args.extend_from_slice(&flags);
    mesh_ok(&d, &args);
    // Every vertex: its height and bands 2 and 3, the same in every file that has it.
    let mut seen: HashMap<(i64, i64), [f64; 3]> = HashMap::new();
    let mut tiles: HashMap<(usize, usize), Vec<(i64, i64)>> = HashMap::new();
    for row in 0..2 {
        for col in 0..3 {
            let path = d.path("tiles").join(format!("tile_r{row}_c{col}.ply"));
            let m = tinsmith_formats::read_mesh(&path).expect("tile mesh");
            let names: Vec<&str> = m.attributes.iter().map(|(n, _)| n.as_str()).collect();
            assert_eq!(names, ["band_2", "band_3"], "{}", path.display());
            for (i, v) in m.vertices.iter().enumerate() {
                let key = (v[0] as i64, v[1] as i64);
                let values = [v[2], m.attributes[0].1[i], m.attributes[1].1[i]];
                assert_eq!(*seen.entry(key).or_insert(values), values, "{key:?}");
                tiles.entry((row, col)).or_default().push(key);
            }
        }
    }
    let on = |tile: (usize, usize), line: &dyn Fn(&(i64, i64)) -> bool| {
        let mut keys: Vec<(i64, i64)> = tiles[&tile].iter().copied().filter(line).collect();
        keys.sort_unstable();
        keys
    };
    for row in 0..2 {
        for (col, x) in [(0, 15), (1, 30)] {
            let (ymin, ymax) = (15 * row as i64, 15 * row as i64 + 15);
            let line = |k: &(i64, i64)| k.0 == x && (ymin..=ymax).contains(&k.1);
            let (left, right) = (on((row, col), &line), on((row, col + 1), &line));
            assert!(left.len() >= 2);
            assert_eq!(left, right, "shared edge x = {x}, tile row {row}");
        }
    }
    for col in 0..3 {
        let line =
            |k: &(i64, i64)| k.1 == 15 && (15 * col as i64..=15 * col as i64 + 15).contains(&k.0);
        assert_eq!(
            on((0, col), &line),
            on((1, col), &line),
            "tile column {col}"
        );
    }
    // The welded mesh has exactly the tiles' vertices, with the same values.
    let welded = tinsmith_formats::read_mesh(&d.path("m.ply")).expect("welded");
    assert_eq!(welded.vertices.len(), seen.len());
    for (i, v) in welded.vertices.iter().enumerate() {
        let values = [v[2], welded.attributes[0].1[i], welded.attributes[1].1[i]];
        assert_eq!(seen[&(v[0] as i64, v[1] as i64)], values);
    }
}

#[test]
fn tiled_bands_refuse_obj_tiles_and_heights_only_formats() {
    let d = Dir::new();
    three_bands(&d);
    let base = [
        "mesh",
        "multi.tif",
        "--bands",
        "1,2",
        "--max-error",
        "1",
        "--tile-size",
        TILE,
    ];
    let mut args = base.to_vec();
    args.extend_from_slice(&["--per-tile", "tiles", "--tile-format", "obj"]);
    assert_fails_naming(&d.run(&args), &["multi.tif", "OBJ"]);
    assert!(!d.path("tiles").exists());
    let mut args = base.to_vec();
    args.extend_from_slice(&["-o", "m.stl"]);
    assert_fails_naming(&d.run(&args), &["multi.tif", "STL"]);
    assert!(!d.path("m.stl").exists());
}

#[test]
fn tiled_bands_in_gltf_keep_each_bound_as_float32_holds_them() {
    let d = Dir::new();
    three_bands(&d);
    let bounds = "1,0.5,0.25";
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.glb",
            "--bands",
            "1,2,3",
            "--max-error",
            bounds,
            "--tile-size",
            TILE,
            "--pixel-coords",
        ],
    );
    assert!(r["tiles"]["count"].as_u64().unwrap() > 1, "{r}");
    assert_eq!(r["variables"].as_array().unwrap().len(), 2, "{r}");
    // Read back from the file: each band against its float32 attribute.
    let v = verify_bands(&d, "m.glb", "1,2,3", bounds);
    assert_eq!(v["variables"].as_array().unwrap().len(), 2, "{v}");
    // A bound float32's rounding alone would use up is refused, naming the band.
    write_band(&d, "big.asc", |x, y| 1.0e9 + (x * 7 + y) as f64);
    stack(&d, "big.tif", &["big.asc"]);
    let o = d.run(&[
        "mesh",
        "multi.tif",
        "-o",
        "n.glb",
        "--bands",
        "1",
        "--attributes",
        "big.tif",
        "--attribute-error",
        "1",
        "--max-error",
        "1",
        "--tile-size",
        TILE,
    ]);
    assert_fails_naming(&o, &["multi.tif", "float32 rounds"]);
    assert!(!d.path("n.glb").exists());
}

#[test]
fn tiled_attributes_from_another_raster_on_the_same_grid() {
    let d = Dir::new();
    write_band(&d, "dem.asc", field(0.3));
    write_band(&d, "other.asc", field(1.7));
    let base = [
        "mesh",
        "dem.asc",
        "--max-error",
        "1",
        "--attribute-error",
        "0.5",
        "--tile-size",
        TILE,
        "--report",
        "r.json",
        "-q",
    ];
    let mut args = base.to_vec();
    args.extend_from_slice(&["-o", "m.ply", "--attributes", "other.asc"]);
    let o = d.run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = crate::variables::report(&d);
    assert_eq!(r["tiles"]["count"], 6, "{r}");
    assert_eq!(r["variables"][0]["name"], "other_band_1", "{r}");
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
    // Elsewhere: refused, naming the file, nothing written.
    crate::variables::write_band_at(&d, "far.asc", (90_000.0, 2000.0, 10.0), field(1.0));
    let mut args = base.to_vec();
    args.extend_from_slice(&["-o", "n.ply", "--attributes", "far.asc"]);
    assert_fails_naming(&d.run(&args), &["far.asc", "does not overlap"]);
    assert!(!d.path("n.ply").exists());
}

#[test]
fn tiled_bands_to_flatgeobuf_carry_each_band_per_triangle() {
    let d = Dir::new();
    three_bands(&d);
    let r = mesh_ok(
        &d,
        &[
            "-o",
            "m.fgb",
            "--bands",
            "1,2,3",
            "--max-error",
            "1,0.5,0.25",
            "--tile-size",
            TILE,
        ],
    );
    assert_eq!(r["tiles"]["count"], 6, "{r}");
    let o = std::process::Command::new("ogrinfo")
        .args(["-so", "-al"])
        .arg(d.path("m.fgb"))
        .output()
        .expect("ogrinfo (GDAL) must be on PATH");
    let info = String::from_utf8_lossy(&o.stdout);
    assert!(info.contains("band_2: Real"), "{info}");
    assert!(info.contains("band_3: Real"), "{info}");
    let count = format!("Feature Count: {}", r["triangles_after"]);
    assert!(info.contains(&count), "{info}");
}
