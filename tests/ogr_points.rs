//! OGR point layers as point input: GeoPackage with Z, Shapefile with a height attribute
//! (`--z-field`), FlatGeobuf points (not a TIN), written from one CSV by ogr2ogr; each
//! gives the CSV's mesh, with the layer's CRS; bad layers are refused naming the file.

use crate::util::{stderr, stdout, Dir};

fn points_csv(n: usize) -> String {
    let mut s = String::from("x,y,z\n");
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..n {
        let (x, y) = (
            (next() * 150_000.0).round() / 1000.0,
            (next() * 150_000.0).round() / 1000.0,
        );
        let z = 200.0 + 6.0 * (x / 25.0).sin() * (y / 40.0).cos() + 0.01 * x;
        s.push_str(&format!(
            "{:.3},{:.3},{z:.3}\n",
            500_000.0 + x,
            4_000_000.0 + y
        ));
    }
    s
}

fn ogr2ogr(dir: &Dir, args: &[&str]) {
    let o = std::process::Command::new("ogr2ogr")
        .args(args)
        .current_dir(dir.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "ogr2ogr {args:?}: {}", stderr(&o));
}

const XY: [&str; 4] = ["-oo", "X_POSSIBLE_NAMES=x", "-oo", "Y_POSSIBLE_NAMES=y"];

#[test]
fn geopackage_shapefile_and_flatgeobuf_points_give_the_csv_mesh_with_their_crs() {
    let dir = Dir::new();
    dir.write("pts.csv", &points_csv(2000));
    let mut gpkg = vec!["-f", "GPKG", "pts.gpkg", "pts.csv", "-a_srs", "EPSG:32633"];
    gpkg.extend(XY);
    gpkg.extend(["-oo", "Z_POSSIBLE_NAMES=z", "-nln", "pts"]);
    ogr2ogr(&dir, &gpkg);
    let mut shp = vec![
        "-f",
        "ESRI Shapefile",
        "pts.shp",
        "pts.csv",
        "-a_srs",
        "EPSG:32633",
    ];
    shp.extend(XY);
    shp.extend(["-oo", "AUTODETECT_TYPE=YES"]);
    ogr2ogr(&dir, &shp);
    ogr2ogr(&dir, &["-f", "FlatGeobuf", "pts.fgb", "pts.gpkg"]);
    let mesh = |input: &str, out: &str, extra: &[&str]| {
        let mut args = vec!["mesh", input, "-o", out, "--max-error", "0.05"];
        args.extend_from_slice(extra);
        let o = dir.run(&args);
        assert!(o.status.success(), "{input}: {}", stderr(&o));
    };
    mesh("pts.csv", "csv.obj", &["--crs", "EPSG:32633"]);
    mesh("pts.gpkg", "gpkg.obj", &[]);
    mesh("pts.shp", "shp.obj", &["--z-field", "z"]);
    mesh("pts.fgb", "fgb.obj", &[]);
    let csv = std::fs::read_to_string(dir.path("csv.obj")).unwrap();
    for out in ["gpkg.obj", "shp.obj", "fgb.obj"] {
        assert_eq!(
            std::fs::read_to_string(dir.path(out)).unwrap(),
            csv,
            "{out}"
        );
        // The layer's CRS, written beside the OBJ.
        let prj = std::fs::read_to_string(dir.path(&out.replace(".obj", ".prj"))).unwrap();
        assert!(prj.contains("UTM zone 33N"), "{out}: {prj}");
    }
    for (input, extra) in [
        ("pts.gpkg", None),
        ("pts.shp", Some("z")),
        ("pts.fgb", None),
    ] {
        let mut args = vec!["verify", input, "gpkg.obj", "--max-error", "0.05"];
        if let Some(z) = extra {
            args.extend(["--z-field", z]);
        }
        let o = dir.run(&args);
        assert!(o.status.success(), "{input}: {}{}", stdout(&o), stderr(&o));
        assert!(stdout(&o).contains("2000 points"), "{}", stdout(&o));
    }
}

#[test]
fn flat_points_without_a_field_and_an_unknown_field_are_refused_naming_the_file() {
    let dir = Dir::new();
    dir.write("pts.csv", &points_csv(100));
    let mut shp = vec!["-f", "ESRI Shapefile", "flat.shp", "pts.csv"];
    shp.extend(XY);
    shp.extend(["-oo", "AUTODETECT_TYPE=YES"]);
    ogr2ogr(&dir, &shp);
    for (extra, problem) in [
        (vec![], "--z-field"),
        (vec!["--z-field", "height"], "no field height"),
    ] {
        let before = dir.files();
        let mut args = vec!["mesh", "flat.shp", "-o", "out.ply", "--max-error", "0.1"];
        args.extend(extra);
        let o = dir.run(&args);
        assert!(!o.status.success());
        let e = stderr(&o);
        assert!(e.contains("flat.shp") && e.contains(problem), "{e}");
        assert_eq!(dir.files(), before);
    }
}
