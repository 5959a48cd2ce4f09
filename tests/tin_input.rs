//! Existing TINs as input: a DEM meshed exactly, then that mesh (PLY, OBJ, LandXML,
//! FlatGeobuf) decimated with its own triangles, every original vertex checked by the
//! verifier and the boundary (outline and a hole) kept; invalid triangulations refused.

use std::collections::HashMap;

use crate::util::{assert_fails_naming, stderr, stdout, Dir};

/// A 60 x 60 DEM of 2 m cells with a 10 x 10 nodata hole, as an ASCII grid.
fn dem_with_hole(d: &Dir) {
    let n = 60;
    let mut text = format!(
        "ncols {n}\nnrows {n}\nxllcorner 500000\nyllcorner 4000000\ncellsize 2\n\
         NODATA_value -9999\n"
    );
    for r in 0..n {
        let row: Vec<String> = (0..n)
            .map(|c| {
                let (x, y) = (c as f64 * 2.0, (n - 1 - r) as f64 * 2.0);
                if (20..30).contains(&r) && (25..35).contains(&c) {
                    "-9999".into()
                } else {
                    format!(
                        "{:.3}",
                        100.0
                            + 0.05 * x
                            + 8.0 * (x / 30.0).sin() * (y / 45.0).cos()
                            + 3.0 * (-(x - y).powi(2) / 800.0).exp()
                    )
                }
            })
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write("g.asc", &text);
}

/// Meshes the DEM exactly into `name` (any mesh format).
fn exact_mesh(d: &Dir, name: &str) {
    let o = d.run(&["mesh", "g.asc", "-o", name, "--max-error", "0", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The sum of the triangles' areas in x, y.
fn area(mesh: &tinsmith_formats::Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .sum()
}

/// The boundary vertices where the boundary turns (outline and holes), as x, y bits.
fn boundary_corners(mesh: &tinsmith_formats::Mesh) -> Vec<[u64; 2]> {
    let mut directed = std::collections::HashSet::new();
    for t in &mesh.triangles {
        for e in 0..3 {
            directed.insert((t[e], t[(e + 1) % 3]));
        }
    }
    let next: HashMap<u32, u32> = directed
        .iter()
        .filter(|(a, b)| !directed.contains(&(*b, *a)))
        .map(|&(a, b)| (a, b))
        .collect();
    let at = |v: u32| mesh.vertices[v as usize];
    let mut corners: Vec<[u64; 2]> = next
        .iter()
        .filter_map(|(&a, &b)| {
            let c = *next.get(&b)?;
            let (p, q, r) = (at(a), at(b), at(c));
            let turn = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
            (turn != 0.0).then_some([q[0].to_bits(), q[1].to_bits()])
        })
        .collect();
    corners.sort_unstable();
    corners
}

fn positions(mesh: &tinsmith_formats::Mesh) -> std::collections::HashSet<[u64; 2]> {
    mesh.vertices
        .iter()
        .map(|v| [v[0].to_bits(), v[1].to_bits()])
        .collect()
}

#[test]
fn a_dem_mesh_decimated_as_a_tin_keeps_the_bound_and_the_boundary() {
    let d = Dir::new();
    dem_with_hole(&d);
    exact_mesh(&d, "full.ply");
    let o = d.run(&[
        "mesh",
        "full.ply",
        "-o",
        "small.ply",
        "--max-error",
        "0.5",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    assert_eq!(report["points_read"], 3500);
    assert_eq!(report["input_triangles"], 6720);
    assert!(report["delaunay_triangles"].is_null());
    let full = tinsmith_formats::read_mesh(&d.path("full.ply")).unwrap();
    let small = tinsmith_formats::read_mesh(&d.path("small.ply")).unwrap();
    assert!(small.triangles.len() * 20 < full.triangles.len());
    // Every original vertex within the bound, by the verifier, from the files; and a
    // tighter bound fails, so the check can fail.
    let o = d.run(&["verify", "full.ply", "small.ply", "--max-error", "0.5"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("3500 points"), "{}", stdout(&o));
    let o = d.run(&["verify", "full.ply", "small.ply", "--max-error", "0.05"]);
    assert!(!o.status.success(), "{}", stdout(&o));
    // The domain is the input's (hole included) and every boundary corner is kept.
    assert!((area(&small) - area(&full)).abs() < 1e-6 * area(&full));
    assert!(area(&full) < 118.0 * 118.0 - 18.0 * 18.0 + 1.0);
    let corners = boundary_corners(&full);
    assert_eq!(corners.len(), 8, "outline and hole corners");
    let kept = positions(&small);
    for c in &corners {
        assert!(kept.contains(c), "corner {c:?} lost");
    }
}

#[test]
fn obj_landxml_and_flatgeobuf_inputs_give_the_same_tin_as_ply() {
    let d = Dir::new();
    dem_with_hole(&d);
    let mut counts = Vec::new();
    for name in ["full.ply", "full.obj", "full.xml", "full.fgb"] {
        exact_mesh(&d, name);
        let out = format!("{name}.small.ply");
        let o = d.run(&["mesh", name, "-o", &out, "--max-error", "0.3", "-q"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let o = d.run(&["verify", name, &out, "--max-error", "0.3"]);
        assert!(o.status.success(), "{name}: {}", stdout(&o));
        let small = tinsmith_formats::read_mesh(&d.path(&out)).unwrap();
        let full = tinsmith_formats::read_mesh(&d.path(name)).unwrap();
        let kept = positions(&small);
        assert!(boundary_corners(&full).iter().all(|c| kept.contains(c)));
        counts.push((small.vertices.len(), small.triangles.len()));
    }
    assert!(counts.iter().all(|&c| c == counts[0]), "{counts:?}");
}

#[test]
fn same_bytes_for_any_thread_count() {
    let d = Dir::new();
    dem_with_hole(&d);
    exact_mesh(&d, "full.ply");
    let mut outputs = Vec::new();
    for threads in ["1", "2", "4"] {
        let out = format!("t{threads}.xml");
        let o = d.run(&[
            "mesh",
            "full.ply",
            "-o",
            &out,
            "--max-error",
            "0.2",
            "--threads",
            threads,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        outputs.push(std::fs::read(d.path(&out)).unwrap());
    }
    assert!(outputs.iter().all(|o| o == &outputs[0]));
}

#[test]
fn the_crs_is_carried_from_the_file_or_given() {
    let d = Dir::new();
    dem_with_hole(&d);
    exact_mesh(&d, "full.ply");
    let o = d.run(&[
        "mesh",
        "full.ply",
        "-o",
        "a.ply",
        "--max-error",
        "0.5",
        "--crs",
        "EPSG:32633",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = d.run(&["mesh", "a.ply", "-o", "b.fgb", "--max-error", "1", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let has_crs = |name: &str| {
        let m = tinsmith_formats::read_mesh(&d.path(name)).unwrap();
        m.crs_wkt.as_deref().is_some_and(|w| w.contains("32633")) || m.epsg == Some(32633)
    };
    assert!(has_crs("b.fgb"));
    // A file without one takes its .prj sidecar.
    let wkt = tinsmith_formats::read_mesh(&d.path("a.ply"))
        .unwrap()
        .crs_wkt
        .unwrap();
    obj(&d, "sq.obj", &SQUARE, &[[1, 2, 3], [1, 3, 4]]);
    let o = d.run(&["mesh", "sq.obj", "-o", "sq.fgb", "--max-error", "0.1", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!has_crs("sq.fgb"));
    d.write("sq.prj", &wkt);
    let o = d.run(&["mesh", "sq.obj", "-o", "sq.fgb", "--max-error", "0.1", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(has_crs("sq.fgb"));
}

#[test]
fn a_grid_of_no_power_of_ten_is_taken_on_its_own_spacing() {
    // 3 arc-second cells: positions on no power-of-ten step within 2^31 steps.
    let d = Dir::new();
    let mut text = "ncols 40\nnrows 30\nxllcorner -120\nyllcorner 45\n\
                    cellsize 0.000833333333333333\n"
        .to_string();
    for r in 0..30 {
        let row: Vec<String> = (0..40)
            .map(|c| format!("{:.2}", 300.0 + 5.0 * ((c * r) as f64 / 50.0).sin()))
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    d.write("geo.asc", &text);
    let o = d.run(&["mesh", "geo.asc", "-o", "geo.ply", "--max-error", "0", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = d.run(&[
        "mesh",
        "geo.ply",
        "-o",
        "small.ply",
        "--max-error",
        "0.5",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path("r.json")).unwrap()).unwrap();
    let spacing = report["lattice_spacing"][0].as_f64().unwrap();
    assert!((spacing - 1.0 / 1200.0).abs() < 1e-12, "{spacing}");
    let o = d.run(&["verify", "geo.ply", "small.ply", "--max-error", "0.5"]);
    assert!(o.status.success(), "{}", stdout(&o));
}

/// An OBJ of `vertices` (x y z) and 1-based `faces`.
fn obj(d: &Dir, name: &str, vertices: &[[f64; 3]], faces: &[[u32; 3]]) {
    let mut text = String::new();
    for v in vertices {
        text.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2]));
    }
    for f in faces {
        text.push_str(&format!("f {} {} {}\n", f[0], f[1], f[2]));
    }
    d.write(name, &text);
}

const SQUARE: [[f64; 3]; 4] = [
    [0.0, 0.0, 1.0],
    [10.0, 0.0, 2.0],
    [10.0, 10.0, 3.0],
    [0.0, 10.0, 4.0],
];

fn refused(d: &Dir, name: &str, words: &[&str]) {
    let o = d.run(&["mesh", name, "-o", "out.ply", "--max-error", "0.1"]);
    let mut names = vec![name];
    names.extend_from_slice(words);
    assert_fails_naming(&o, &names);
    assert!(!d.path("out.ply").exists(), "{:?}", d.files());
}

#[test]
fn flipped_and_overlapping_triangles_are_refused() {
    let d = Dir::new();
    obj(&d, "flipped.obj", &SQUARE, &[[1, 2, 3], [1, 4, 3]]);
    refused(&d, "flipped.obj", &["opposite directions"]);
    // Both diagonals: the triangles cross.
    obj(
        &d,
        "crossed.obj",
        &SQUARE,
        &[[1, 2, 3], [1, 3, 4], [1, 2, 4]],
    );
    refused(&d, "crossed.obj", &["overlap"]);
    // A small triangle lying on a large one, sharing nothing.
    let mut v = SQUARE.to_vec();
    v.extend([[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]]);
    obj(&d, "stacked.obj", &v, &[[1, 2, 3], [1, 3, 4], [5, 6, 7]]);
    refused(&d, "stacked.obj", &["overlap"]);
    obj(&d, "flat.obj", &SQUARE, &[[1, 2, 2]]);
    refused(&d, "flat.obj", &["degenerate"]);
    // The same square is fine.
    obj(&d, "ok.obj", &SQUARE, &[[1, 2, 3], [1, 3, 4]]);
    let o = d.run(&["mesh", "ok.obj", "-o", "ok.ply", "--max-error", "0.1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn duplicate_vertices_and_unusable_coordinates_are_refused() {
    let d = Dir::new();
    let mut v = SQUARE.to_vec();
    v.push([10.0, 10.0, 7.0]);
    obj(&d, "dup.obj", &v, &[[1, 2, 3], [1, 5, 4]]);
    refused(&d, "dup.obj", &["same x, y"]);
    // An identical copy is merged.
    v[4][2] = 3.0;
    obj(&d, "copy.obj", &v, &[[1, 2, 3], [1, 5, 4]]);
    let o = d.run(&["mesh", "copy.obj", "-o", "copy.ply", "--max-error", "0.1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("merged"), "{}", stderr(&o));
    // No power-of-ten lattice and no regular spacing holds these x.
    let mut v = SQUARE.to_vec();
    v[1][0] = std::f64::consts::PI;
    obj(&d, "third.obj", &v, &[[1, 2, 3], [1, 3, 4]]);
    refused(&d, "third.obj", &["x: ", "regular spacing"]);
}
