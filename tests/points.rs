//! Point input: `mesh` and `verify` on LAS, LAZ and XYZ/CSV text generated here, every
//! point checked by the independent verifier; the duplicates rules; bad point files.

use crate::util::{stderr, stdout, Dir};

/// A seeded generator (xorshift), so that fixtures are the same on every run.
struct Seeded(u64);

impl Seeded {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A smooth surface with a ridge, in metres over a 200 m square.
fn surface(x: f64, y: f64) -> f64 {
    100.0
        + 0.05 * x
        + 8.0 * (x / 30.0).sin() * (y / 45.0).cos()
        + 3.0 * (-(x - y).powi(2) / 800.0).exp()
}

/// `n` points at random positions (millimetres) with heights on the surface plus noise
/// below 2 cm, around UTM-sized coordinates.
fn random_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Seeded(seed);
    (0..n)
        .map(|_| {
            let (x, y) = (
                (r.next() * 200_000.0).round() / 1000.0,
                (r.next() * 200_000.0).round() / 1000.0,
            );
            let z = ((surface(x, y) + 0.02 * r.next()) * 1000.0).round() / 1000.0;
            [500_000.0 + x, 4_000_000.0 + y, z]
        })
        .collect()
}

fn csv(points: &[[f64; 3]], delimiter: &str, header: bool) -> String {
    let mut s = String::new();
    if header {
        s.push_str(&format!("x{delimiter}y{delimiter}z\n"));
    }
    for p in points {
        s.push_str(&format!(
            "{:.3}{delimiter}{:.3}{delimiter}{:.3}\n",
            p[0], p[1], p[2]
        ));
    }
    s
}

/// Writes a LAS or LAZ file (by extension) of `points` with a millimetre scale: each
/// point with its class and withheld flag, and an optional WKT CRS record.
fn write_las(path: &std::path::Path, points: &[([f64; 3], u8, bool)], wkt: Option<&str>) {
    let mut builder = las::Builder::from((1, 4));
    builder.point_format = las::point::Format::new(6).unwrap();
    builder.point_format.is_compressed = path.extension().is_some_and(|e| e == "laz");
    let t = |offset| las::Transform {
        scale: 0.001,
        offset,
    };
    builder.transforms = las::Vector {
        x: t(500_000.0),
        y: t(4_000_000.0),
        z: t(0.0),
    };
    let mut header = builder.into_header().unwrap();
    if let Some(wkt) = wkt {
        header.set_wkt_crs(wkt.as_bytes().to_vec()).unwrap();
    }
    let mut writer = las::Writer::from_path(path, header).unwrap();
    for &(p, class, withheld) in points {
        let point = las::Point {
            x: p[0],
            y: p[1],
            z: p[2],
            classification: las::point::Classification::new(class).unwrap(),
            is_withheld: withheld,
            return_number: 1,
            gps_time: Some(0.0),
            number_of_returns: 1,
            ..Default::default()
        };
        writer.write_point(point).unwrap();
    }
    writer.close().unwrap();
}

fn report(dir: &Dir, name: &str) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.path(name)).unwrap()).unwrap()
}

#[test]
fn text_points_are_all_within_the_bound_by_the_independent_verifier() {
    let dir = Dir::new();
    let points = random_points(3000, 11);
    dir.write("pts.csv", &csv(&points, ",", true));
    let o = dir.run(&[
        "mesh",
        "pts.csv",
        "-o",
        "tin.ply",
        "--max-error",
        "0.05",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = report(&dir, "r.json");
    assert_eq!(r["points_read"], 3000);
    assert_eq!(r["lattice_spacing"][0], 0.001);
    let (kept, full) = (
        r["triangles"].as_u64().unwrap(),
        r["delaunay_triangles"].as_u64().unwrap(),
    );
    assert!(kept * 3 < full, "{kept} of {full} triangles kept");
    assert!(r["measured_max_error"].as_f64().unwrap() <= 0.05);
    let o = dir.run(&["verify", "pts.csv", "tin.ply", "--max-error", "0.05"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("3000 points") && stdout(&o).contains("passed"),
        "{}",
        stdout(&o)
    );
    // The same mesh at a tenth of the bound does not pass: the check can fail.
    let o = dir.run(&["verify", "pts.csv", "tin.ply", "--max-error", "0.005"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("FAILED"), "{}", stdout(&o));
}

#[test]
fn every_delimiter_gives_the_same_mesh() {
    let dir = Dir::new();
    let points = random_points(500, 5);
    let mut meshes = Vec::new();
    for (name, delimiter, header) in [
        ("a.csv", ",", true),
        ("b.txt", ";", false),
        ("c.xyz", "\t", false),
        ("d.xyz", "  ", true),
    ] {
        dir.write(name, &csv(&points, delimiter, header));
        let out = format!("{name}.ply");
        let o = dir.run(&["mesh", name, "-o", &out, "--max-error", "0.1", "-q"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        meshes.push(std::fs::read(dir.path(&out)).unwrap());
    }
    assert!(meshes.windows(2).all(|w| w[0] == w[1]));
}

#[test]
fn same_bytes_for_any_thread_count_and_every_format_verifies() {
    let dir = Dir::new();
    dir.write("pts.csv", &csv(&random_points(800, 3), ",", false));
    let mut runs = Vec::new();
    for threads in ["1", "2", "4"] {
        let out = format!("t{threads}.ply");
        let o = dir.run(&[
            "mesh",
            "pts.csv",
            "-o",
            &out,
            "--max-error",
            "0.08",
            "--threads",
            threads,
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        runs.push(std::fs::read(dir.path(&out)).unwrap());
    }
    assert!(runs.windows(2).all(|w| w[0] == w[1]));
    for out in ["m.obj", "m.stl", "m.glb", "m.fgb", "m.xml"] {
        let o = dir.run(&[
            "mesh",
            "pts.csv",
            "-o",
            out,
            "--max-error",
            "0.08",
            "--crs",
            "EPSG:32633",
            "-q",
        ]);
        assert!(o.status.success(), "{out}: {}", stderr(&o));
        let o = dir.run(&["verify", "pts.csv", out, "--max-error", "0.08"]);
        assert!(o.status.success(), "{out}: {}{}", stdout(&o), stderr(&o));
    }
    let o = dir.run(&[
        "mesh",
        "pts.csv",
        "-o",
        "m.geojson",
        "--max-error",
        "0.08",
        "--crs",
        "EPSG:32633",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let geojson = std::fs::read_to_string(dir.path("m.geojson")).unwrap();
    // UTM 33N at x = 500 km is 15° E, at y = 4000 km about 36° N.
    assert!(
        geojson.contains("[15.") && geojson.contains(",36."),
        "not in WGS84"
    );
}

#[test]
fn duplicates_follow_the_rule_and_are_counted() {
    let dir = Dir::new();
    // A flat square with three points at its centre, at 0, 4 and 8.
    let mut text = String::from("0 0 0\n10 0 0\n0 10 0\n10 10 0\n5 5 0\n5 5 4\n5 5 8\n2 7 0\n");
    text.push_str("7 2 0\n");
    dir.write("dup.xyz", &text);
    for (rule, height) in [
        ("lowest", 0.0),
        ("highest", 8.0),
        ("mean", 4.0),
        ("first", 0.0),
    ] {
        let out = format!("{rule}.ply");
        let o = dir.run(&[
            "mesh",
            "dup.xyz",
            "-o",
            &out,
            "--max-error",
            "0.01",
            "--duplicates",
            rule,
            "--report",
            "r.json",
        ]);
        assert!(o.status.success(), "{rule}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("2 points merged"),
            "{rule}: {}",
            stderr(&o)
        );
        assert_eq!(report(&dir, "r.json")["duplicates_merged"], 2);
        let o = dir.run(&[
            "verify",
            "dup.xyz",
            &out,
            "--max-error",
            "0.01",
            "--duplicates",
            rule,
        ]);
        assert!(o.status.success(), "{rule}: {}", stdout(&o));
        // Measured with another rule's height, the centre is off by 4 or more.
        let other = if height == 8.0 { "lowest" } else { "highest" };
        let o = dir.run(&[
            "verify",
            "dup.xyz",
            &out,
            "--max-error",
            "1",
            "--duplicates",
            other,
        ]);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{rule} against {other}: {}",
            stdout(&o)
        );
    }
}

/// The points of `las_points` with classes: ground (2) on the surface, vegetation (5)
/// 10 m above it, and some ground points withheld 50 m below it.
fn classified_points() -> Vec<([f64; 3], u8, bool)> {
    random_points(1500, 21)
        .into_iter()
        .enumerate()
        .map(|(i, p)| match i % 5 {
            0 => ([p[0], p[1], p[2] + 10.0], 5, false),
            1 if i % 15 == 1 => ([p[0], p[1], p[2] - 50.0], 2, true),
            _ => (p, 2, false),
        })
        .collect()
}

#[test]
fn las_and_laz_read_the_same_classes_and_give_the_same_mesh() {
    let dir = Dir::new();
    let points = classified_points();
    let ground = points.iter().filter(|p| p.1 == 2).count();
    let kept = points.iter().filter(|p| p.1 == 2 && !p.2).count();
    let wkt = "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",15],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",0],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"32633\"]]";
    write_las(&dir.path("p.las"), &points, Some(wkt));
    write_las(&dir.path("p.laz"), &points, Some(wkt));
    assert!(
        std::fs::metadata(dir.path("p.laz")).unwrap().len()
            < std::fs::metadata(dir.path("p.las")).unwrap().len()
    );
    for input in ["p.las", "p.laz"] {
        let out = format!("{input}.ply");
        let o = dir.run(&[
            "mesh",
            input,
            "-o",
            &out,
            "--max-error",
            "0.05",
            "--no-withheld",
            "--report",
            "r.json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stderr(&o).contains("ground points only"), "{}", stderr(&o));
        assert_eq!(report(&dir, "r.json")["points_read"], kept as u64);
        assert_eq!(
            report(&dir, "r.json")["points_in_file"],
            points.len() as u64
        );
        let o = dir.run(&[
            "verify",
            input,
            &out,
            "--max-error",
            "0.05",
            "--no-withheld",
        ]);
        assert!(o.status.success(), "{}", stdout(&o));
        // The CRS of the WKT record is written.
        let ply = std::fs::read(dir.path(&out)).unwrap();
        assert!(String::from_utf8_lossy(&ply).contains("UTM zone 33N"));
    }
    assert_eq!(
        std::fs::read(dir.path("p.las.ply")).unwrap(),
        std::fs::read(dir.path("p.laz.ply")).unwrap()
    );
    // With the withheld points, 50 m below, kept: the mesh reaches down to them.
    let o = dir.run(&[
        "mesh",
        "p.las",
        "-o",
        "w.ply",
        "--max-error",
        "0.05",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(report(&dir, "r.json")["points_read"], ground as u64);
    // Vegetation only, and every class.
    let o = dir.run(&[
        "mesh",
        "p.las",
        "-o",
        "v.ply",
        "--max-error",
        "0.05",
        "--classes",
        "5",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        report(&dir, "r.json")["points_read"],
        (points.len() - ground) as u64
    );
    let o = dir.run(&[
        "verify",
        "p.las",
        "v.ply",
        "--max-error",
        "0.05",
        "--classes",
        "5",
    ]);
    assert!(o.status.success(), "{}", stdout(&o));
    let o = dir.run(&["verify", "p.las", "v.ply", "--max-error", "0.05"]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "ground against the vegetation mesh: {}",
        stdout(&o)
    );
}

/// The venv's Python, with laspy and its LAZ backend (lazrs), an independent LAS reader.
fn laspy() -> std::path::PathBuf {
    let python = crate::util::venv_python();
    let ok = std::process::Command::new(&python)
        .args(["-c", "import laspy, lazrs"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "oracle missing: laspy[lazrs] in .venv; run `make deps`");
    python
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn laspy_reads_the_points_our_mesh_is_within_the_bound_of() {
    let python = laspy();
    let dir = Dir::new();
    let points = classified_points();
    for input in ["p.las", "p.laz"] {
        write_las(&dir.path(input), &points, None);
        let out = format!("{input}.ply");
        let o = dir.run(&[
            "mesh",
            input,
            "-o",
            &out,
            "--max-error",
            "0.03",
            "--no-withheld",
            "--report",
            "r.json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        // laspy decodes the file on its own and writes the ground points it finds, not
        // withheld, as text: our mesh must be within the bound of every one of them.
        let script = format!(
            "import laspy, numpy as np\n\
             las = laspy.read('{input}')\n\
             keep = (np.asarray(las.classification) == 2) & ~np.asarray(las.withheld, dtype=bool)\n\
             xyz = np.column_stack([las.x[keep], las.y[keep], las.z[keep]])\n\
             np.savetxt('{input}.csv', xyz, fmt='%.3f', delimiter=',')\n\
             print(int(keep.sum()), len(las.points))"
        );
        let o = std::process::Command::new(&python)
            .args(["-c", &script])
            .current_dir(dir.path(""))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        let counts: Vec<u64> = stdout(&o)
            .split_whitespace()
            .map(|c| c.parse().unwrap())
            .collect();
        let r = report(&dir, "r.json");
        assert_eq!(
            counts,
            vec![
                r["points_read"].as_u64().unwrap(),
                r["points_in_file"].as_u64().unwrap()
            ]
        );
        let csv = format!("{input}.csv");
        let o = dir.run(&["verify", &csv, &out, "--max-error", "0.03"]);
        assert!(o.status.success(), "{input}: {}{}", stdout(&o), stderr(&o));
        assert!(
            stdout(&o).contains(&format!("{} points", counts[0])),
            "{}",
            stdout(&o)
        );
    }
}

/// COPC (LAZ 1.4 in an octree of variable-size chunks) written by copclib, an independent
/// writer, from the LAS file of the same points: the same points are read (laspy agrees
/// on the count), so the same mesh, byte for byte, with the same CRS.
#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn copc_from_another_writer_gives_the_las_mesh() {
    let python = laspy();
    let dir = Dir::new();
    let points = classified_points();
    let wkt = "PROJCS[\"WGS 84 / UTM zone 33N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",15],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",0],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"32633\"]]";
    write_las(&dir.path("p.las"), &points, Some(wkt));
    let o = std::process::Command::new(&python)
        .arg(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracles/copc_write.py"))
        .args(["p.las", "p.copc.laz", "3"])
        .current_dir(dir.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "copclib: {}", stderr(&o));
    let nodes: usize = stdout(&o).trim().parse().unwrap();
    assert!(nodes > 8, "an octree of several chunks, got {nodes} nodes");
    let args = |input: &str, out: &str, report: &str| {
        let o = dir.run(&[
            "mesh",
            input,
            "-o",
            out,
            "--max-error",
            "0.03",
            "--no-withheld",
            "--report",
            report,
        ]);
        assert!(o.status.success(), "{input}: {}", stderr(&o));
    };
    args("p.las", "las.ply", "las.json");
    args("p.copc.laz", "copc.ply", "copc.json");
    let (las, copc) = (report(&dir, "las.json"), report(&dir, "copc.json"));
    let kept = points.iter().filter(|p| p.1 == 2 && !p.2).count() as u64;
    for r in [&las, &copc] {
        assert_eq!(r["points_read"].as_u64(), Some(kept));
        assert_eq!(r["points_in_file"].as_u64(), Some(points.len() as u64));
    }
    assert!(
        std::fs::read(dir.path("las.ply")).unwrap() == std::fs::read(dir.path("copc.ply")).unwrap(),
        "the COPC file's mesh differs from the LAS file's"
    );
    assert!(
        String::from_utf8_lossy(&std::fs::read(dir.path("copc.ply")).unwrap())
            .contains("UTM zone 33N"),
        "the COPC file's CRS is carried to the mesh"
    );
    // laspy reads the COPC file on its own: our mesh is within the bound of its points.
    let script = "import laspy, numpy as np\n\
         las = laspy.read('p.copc.laz')\n\
         keep = (np.asarray(las.classification) == 2) & ~np.asarray(las.withheld, dtype=bool)\n\
         np.savetxt('copc.csv', np.column_stack([las.x[keep], las.y[keep], las.z[keep]]), fmt='%.3f', delimiter=',')\n\
         print(int(keep.sum()))";
    let o = std::process::Command::new(&python)
        .args(["-c", script])
        .current_dir(dir.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), kept.to_string());
    let o = dir.run(&["verify", "copc.csv", "copc.ply", "--max-error", "0.03"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
}

/// Runs `mesh` on `input` and checks the failure: non-zero exit, the file and `problem`
/// named, and no output left beside the input.
fn refused(dir: &Dir, input: &str, problem: &str) {
    let before = dir.files();
    let o = dir.run(&[
        "mesh",
        input,
        "-o",
        "out.ply",
        "--max-error",
        "0.1",
        "--report",
        "r.json",
    ]);
    assert!(!o.status.success(), "{input} was accepted");
    let e = stderr(&o);
    assert!(e.contains(input) && e.contains(problem), "{input}: {e}");
    assert_eq!(dir.files(), before, "{input} left output");
}

#[test]
fn bad_text_points_are_refused_naming_the_file() {
    let dir = Dir::new();
    dir.write("two.csv", "0,0,1\n1,1,2\n1,1,3\n");
    refused(&dir, "two.csv", "fewer than 3 distinct points");
    dir.write("line.csv", "0,0,1\n1,1,2\n2,2,3\n5,5,0\n");
    refused(&dir, "line.csv", "collinear");
    dir.write("nan.csv", "0,0,1\n1,0,2\nnan,2,3\n");
    refused(&dir, "nan.csv", "line 3");
    dir.write("inf.csv", "0,0,1\n1,0,2\n2,2,inf\n");
    refused(&dir, "inf.csv", "not finite");
    dir.write("empty.csv", "x,y,z\n");
    refused(&dir, "empty.csv", "fewer than 3 distinct points");
}

#[test]
fn bad_las_files_are_refused_naming_the_file() {
    let dir = Dir::new();
    let points = classified_points();
    write_las(&dir.path("count.las"), &points, None);
    // The header's point count (LAS 1.4: u64 at byte 247, legacy u32 at 107) says more.
    let mut bytes = std::fs::read(dir.path("count.las")).unwrap();
    let more = points.len() as u64 + 10;
    bytes[247..255].copy_from_slice(&more.to_le_bytes());
    bytes[107..111].copy_from_slice(&(more as u32).to_le_bytes());
    std::fs::write(dir.path("count.las"), &bytes).unwrap();
    refused(
        &dir,
        "count.las",
        "declares 1510 points but the file holds 1500",
    );
    // ... or fewer: read as a smaller cloud without the check.
    let fewer = points.len() as u64 - 10;
    bytes[247..255].copy_from_slice(&fewer.to_le_bytes());
    bytes[107..111].copy_from_slice(&(fewer as u32).to_le_bytes());
    std::fs::write(dir.path("fewer.las"), &bytes).unwrap();
    refused(
        &dir,
        "fewer.las",
        "declares 1490 points but the file holds 1500",
    );
    write_las(&dir.path("cut.laz"), &points, None);
    let bytes = std::fs::read(dir.path("cut.laz")).unwrap();
    std::fs::write(dir.path("cut.laz"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    // LASzip keeps its chunk table at the end: the reader fails when opening.
    refused(&dir, "cut.laz", "truncated or corrupt");
    std::fs::write(dir.path("junk.las"), b"not a LAS file at all").unwrap();
    refused(&dir, "junk.las", "junk.las");
}

#[test]
fn raster_only_decimation_choices_are_refused_and_the_greedy_order_taken() {
    let dir = Dir::new();
    dir.write("p.csv", &csv(&random_points(200, 5), ",", true));
    for (flags, named) in [
        (&["--initial-mesh", "rtin"][..], "--initial-mesh"),
        (&["--flip-rounds", "1"][..], "--flip-rounds"),
        (&["--extend-rounds", "1"][..], "--extend-rounds"),
    ] {
        let mut args = vec!["mesh", "p.csv", "-o", "out.ply", "--max-error", "0.1"];
        args.extend_from_slice(flags);
        let o = dir.run(&args);
        assert!(!o.status.success(), "{flags:?} was accepted");
        let e = stderr(&o);
        assert!(e.contains("p.csv") && e.contains(named), "{flags:?}: {e}");
        assert!(!dir.path("out.ply").exists(), "{flags:?} left output");
    }
    // What points do take: the default start, or the whole triangulation named, and
    // either order (the greedy one another mesh, as the verifier finds within the bound).
    let o = dir.run(&[
        "mesh",
        "p.csv",
        "-o",
        "out.ply",
        "--max-error",
        "0.1",
        "--initial-mesh",
        "full",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = dir.run(&[
        "mesh",
        "p.csv",
        "-o",
        "g.ply",
        "--max-error",
        "0.1",
        "--order",
        "greedy",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sweep = std::fs::read(dir.path("out.ply")).unwrap();
    assert_ne!(sweep, std::fs::read(dir.path("g.ply")).unwrap());
    let o = dir.run(&["verify", "p.csv", "g.ply", "--max-error", "0.1"]);
    assert!(o.status.success(), "{} {}", stdout(&o), stderr(&o));
}
