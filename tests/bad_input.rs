//! Each bad input gives one clear line naming the file, exit code 2 and no output file.

use crate::util::{assert_fails_naming, fixture, stderr, Dir};

fn dem() -> String {
    fixture("tintn_valid_raster_3857.tif")
}

/// A VRT that stretches the 100 x 80 fixture to `width` x `height` samples (bilinear, so
/// little of it is flat); declaring it reads nothing.
fn stretched_dem(width: u32, height: u32) -> String {
    format!(
        r#"<VRTDataset rasterXSize="{width}" rasterYSize="{height}">
  <VRTRasterBand dataType="Float32" band="1">
    <NoDataValue>-3.4028234663852886e+38</NoDataValue>
    <SimpleSource resampling="bilinear">
      <SourceFilename relativeToVRT="0">{}</SourceFilename>
      <SourceBand>1</SourceBand>
      <SrcRect xOff="0" yOff="0" xSize="100" ySize="80"/>
      <DstRect xOff="0" yOff="0" xSize="{width}" ySize="{height}"/>
    </SimpleSource>
  </VRTRasterBand>
</VRTDataset>
"#,
        dem()
    )
}

#[test]
fn missing_input_file() {
    let d = Dir::new();
    let o = d.run(&["mesh", "nope.tif", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["nope.tif"]);
    assert!(d.files().is_empty());
}

#[test]
fn input_that_is_not_a_raster() {
    let d = Dir::new();
    d.write("notes.doc", "hello, I am not a raster\n");
    let o = d.run(&["mesh", "notes.doc", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["notes.doc", "raster"]);
    // A .txt file is read as x y z points: it is refused as text that holds none.
    d.write("notes.txt", "hello, I am not a raster\n");
    let o = d.run(&["mesh", "notes.txt", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["notes.txt", "line 1", "columns"]);
    assert_eq!(d.files(), vec!["notes.doc", "notes.txt"]);
}

#[cfg(unix)]
#[test]
fn a_device_as_input_is_named_as_not_a_file() {
    // /dev/zero has length 0 and was reported as "an empty file".
    let d = Dir::new();
    for args in [
        vec!["mesh", "/dev/zero", "-o", "out.ply", "--max-error", "1"],
        vec!["info", "/dev/zero"],
    ] {
        let o = d.run(&args);
        assert_fails_naming(&o, &["/dev/zero", "device, not a file"]);
        assert!(!stderr(&o).contains("empty"), "{}", stderr(&o));
    }
    assert!(d.files().is_empty());
}

/// The CT fixture with two malformed tags (an ImageDescription past the end of the file, an
/// XResolution of an unknown type), on which GDAL warns when opening it, and cut to
/// `keep` of its bytes.
fn tiff_with_bad_tags(keep: f64) -> Vec<u8> {
    let mut bytes = std::fs::read(fixture("ct_brain_crop_128_i16.tif")).unwrap();
    assert_eq!(
        &bytes[..8],
        b"II*\0\x08\0\0\0",
        "a little-endian TIFF, first IFD at 8"
    );
    let entries = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    for i in 0..entries {
        let at = 10 + 12 * i;
        match u16::from_le_bytes([bytes[at], bytes[at + 1]]) {
            270 => bytes[at + 8..at + 12].copy_from_slice(&1_000_000u32.to_le_bytes()),
            282 => bytes[at + 2..at + 4].copy_from_slice(&99u16.to_le_bytes()),
            _ => {}
        }
    }
    bytes.truncate((bytes.len() as f64 * keep) as usize);
    bytes
}

#[test]
fn a_malformed_tiff_gives_our_one_line_error_and_no_gdal_warnings() {
    // GDAL's warnings about the bad tags came first, then the error; they are kept for a
    // run that succeeds.
    let d = Dir::new();
    std::fs::write(d.path("cut.tif"), tiff_with_bad_tags(0.5)).unwrap();
    let o = d.run(&["mesh", "cut.tif", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["cut.tif"]);
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("arning"), "{err}");
    assert_eq!(d.files(), vec!["cut.tif"]);

    std::fs::write(d.path("whole.tif"), tiff_with_bad_tags(1.0)).unwrap();
    let o = d.run(&[
        "mesh",
        "whole.tif",
        "-o",
        "out.ply",
        "--max-error",
        "1",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("GDAL warning: "), "{}", stderr(&o));
}

#[test]
fn a_vrt_whose_source_is_missing_says_so_once() {
    // The message quoted GDAL's reason, then the gdal crate's wrapper of the same reason
    // ("CPL error class: '3', error number: '4', error msg: ...").
    let d = Dir::new();
    let vrt = stretched_dem(50, 40).replace(&dem(), "gone.tif");
    d.write("broken.vrt", &vrt);
    let o = d.run(&["mesh", "broken.vrt", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["broken.vrt", "gone.tif: No such file"]);
    let err = stderr(&o);
    assert!(!err.contains("CPL error"), "{err}");
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
    assert_eq!(d.files(), vec!["broken.vrt"]);
}

#[test]
fn an_output_over_a_file_the_input_is_read_from_is_refused() {
    // Only the input's own path was protected: a VRT's source (or a PNG's .aux.xml
    // georeferencing) was overwritten and the run exited 0.
    let d = Dir::new();
    std::fs::copy(dem(), d.path("src.tif")).unwrap();
    let vrt = stretched_dem(50, 40).replace(
        &format!("relativeToVRT=\"0\">{}<", dem()),
        "relativeToVRT=\"1\">src.tif<",
    );
    d.write("v.vrt", &vrt);
    let before = std::fs::read(d.path("src.tif")).unwrap();
    let mesh = [
        "mesh",
        "v.vrt",
        "-o",
        "src.tif",
        "--format",
        "ply",
        "--max-error",
        "1",
    ];
    let tiled = ["--tile-size", "16"];
    for args in [&mesh[..], &[&mesh[..], &tiled[..]].concat()] {
        let o = d.run(args);
        assert_fails_naming(&o, &["src.tif", "v.vrt", "read from"]);
    }
    let o = d.run(&["contour", "v.vrt", "-o", "src.tif", "--levels", "0"]);
    assert_eq!(o.status.code(), Some(2));
    // The report too, and the OBJ's .prj sidecar.
    let o = d.run(&[
        "mesh",
        "v.vrt",
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--report",
        "src.tif",
    ]);
    assert_fails_naming(&o, &["src.tif", "read from"]);
    std::fs::copy(d.path("src.tif"), d.path("src.prj")).unwrap();
    std::fs::write(
        d.path("v.vrt"),
        vrt.replace(
            "<SourceFilename relativeToVRT=\"1\">src.tif",
            "<SourceFilename relativeToVRT=\"1\">src.prj",
        ),
    )
    .unwrap();
    let o = d.run(&["mesh", "v.vrt", "-o", "src.obj", "--max-error", "1"]);
    assert_fails_naming(&o, &["src.obj", "src.prj", "belongs to the input"]);
    assert_eq!(std::fs::read(d.path("src.tif")).unwrap(), before);
    assert_eq!(std::fs::read(d.path("src.prj")).unwrap(), before);
    assert_eq!(d.files(), vec!["src.prj", "src.tif", "v.vrt"]);
    // A raster read from inside an archive: the archive was overwritten.
    let o = std::process::Command::new("gdal_translate")
        .args(["-q", "-of", "AAIGrid", &dem(), "/vsizip/a.zip/dem.asc"])
        .current_dir(d.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let zip = std::fs::read(d.path("a.zip")).unwrap();
    let o = d.run(&[
        "mesh",
        "/vsizip/a.zip/dem.asc",
        "-o",
        "a.zip",
        "--format",
        "ply",
        "--max-error",
        "1",
    ]);
    assert_fails_naming(&o, &["a.zip", "read from"]);
    assert_eq!(std::fs::read(d.path("a.zip")).unwrap(), zip);
}

#[test]
fn a_singular_geotransform_is_refused_unless_pixel_coords() {
    // A pixel size of 0 put every vertex at one point: mesh wrote it with exit 0, contour
    // blamed the levels, tiles said the raster lay outside latitudes -90..90.
    let d = Dir::new();
    let vrt = stretched_dem(50, 40).replace(
        "<VRTRasterBand",
        "<SRS>EPSG:4326</SRS><GeoTransform>10, 0, 0, 50, 0, 0</GeoTransform><VRTRasterBand",
    );
    d.write("flat.vrt", &vrt);
    let runs: [&[&str]; 5] = [
        &["mesh", "flat.vrt", "-o", "m.ply", "--max-error", "1"],
        &[
            "mesh",
            "flat.vrt",
            "-o",
            "m.ply",
            "--max-error",
            "1",
            "--tile-size",
            "16",
        ],
        &[
            "mesh",
            "flat.vrt",
            "--per-tile",
            "p",
            "--max-error",
            "1",
            "--tile-size",
            "16",
        ],
        &["contour", "flat.vrt", "-o", "c.geojson", "--interval", "10"],
        &["tiles", "flat.vrt", "-o", "t"],
    ];
    for args in runs {
        let o = d.run(args);
        assert_fails_naming(&o, &["flat.vrt", "singular"]);
    }
    assert_eq!(d.files(), vec!["flat.vrt"]);
    let o = d.run(&[
        "mesh",
        "flat.vrt",
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--pixel-coords",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_geotransform_that_cannot_place_samples_apart_is_refused() {
    // Pixels of 1e-12 m at x = 500 km: mesh wrote every vertex at one point with exit 0
    // (and verify then refused its own mesh); a NaN origin was called "singular".
    let d = Dir::new();
    for (transform, problem) in [
        ("500000, 1e-12, 0, 4000000, 0, -1e-12", "pixels too small"),
        ("nan, 10, 0, 4000000, 0, -10", "not a finite number"),
    ] {
        let vrt = stretched_dem(50, 40).replace(
            "<VRTRasterBand",
            &format!("<SRS>EPSG:32633</SRS><GeoTransform>{transform}</GeoTransform><VRTRasterBand"),
        );
        d.write("odd.vrt", &vrt);
        let runs: [&[&str]; 3] = [
            &["mesh", "odd.vrt", "-o", "m.ply", "--max-error", "1"],
            &["contour", "odd.vrt", "-o", "c.geojson", "--interval", "10"],
            &["verify", "odd.vrt", "m.ply"],
        ];
        for args in runs {
            let o = d.run(args);
            assert_fails_naming(&o, &["odd.vrt", problem]);
        }
        assert_eq!(d.files(), vec!["odd.vrt"]);
    }
    // Large but representable: 10 m pixels at 1e12 m still map back.
    let vrt = stretched_dem(50, 40).replace(
        "<VRTRasterBand",
        "<SRS>EPSG:32633</SRS><GeoTransform>1e12, 10, 0, 1e12, 0, -10</GeoTransform><VRTRasterBand",
    );
    d.write("far.vrt", &vrt);
    let o = d.run(&["mesh", "far.vrt", "-o", "m.ply", "--max-error", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = d.run(&["verify", "far.vrt", "m.ply", "--max-error", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_prj_sidecar_that_is_not_ours_is_not_replaced() {
    // OBJ, STL and glTF write their CRS to a `.prj` beside them: that replaced a
    // shapefile's `.prj` of the same name, and a read-only one, without a word; and
    // `-o /dev/null` made /dev/null.prj.
    let d = Dir::new();
    d.write("roads.prj", "GEOGCS[\"elsewhere\"]");
    d.write("roads.shp", "");
    let o = d.run(&["mesh", &dem(), "-o", "roads.obj", "--max-error", "5"]);
    assert_fails_naming(&o, &["roads.obj", "roads.prj", "another CRS"]);
    assert_eq!(
        std::fs::read_to_string(d.path("roads.prj")).unwrap(),
        "GEOGCS[\"elsewhere\"]"
    );
    assert_eq!(d.files(), vec!["roads.prj", "roads.shp"]);
    // A directory in the sidecar's place is named as one (it said "another CRS").
    std::fs::create_dir(d.path("dirs.prj")).unwrap();
    let o = d.run(&["mesh", &dem(), "-o", "dirs.obj", "--max-error", "5"]);
    assert_fails_naming(&o, &["dirs.obj", "dirs.prj", "is a directory"]);
    std::fs::remove_dir(d.path("dirs.prj")).unwrap();
    // An earlier mesh's sidecar is replaced, and one with the same CRS even without it.
    let o = d.run(&["mesh", &dem(), "-o", "m.obj", "--max-error", "5", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = d.run(&["mesh", &dem(), "-o", "m.obj", "--max-error", "9", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(d.path("m.obj")).unwrap();
    let o = d.run(&["mesh", &dem(), "-o", "m.obj", "--max-error", "9", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A GeoTIFF reads no `.prj`: the one named like it is an earlier mesh's sidecar, not
    // the input's, so meshing into the input's name works again (it was refused).
    std::fs::copy(dem(), d.path("g.tif")).unwrap();
    for _ in 0..2 {
        let o = d.run(&["mesh", "g.tif", "-o", "g.obj", "--max-error", "9", "-q"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(d.path("g.prj").is_file());
    }
    // The same CRS spelled otherwise (ESRI's WKT, as GIS tools write `.prj` files) too.
    let esri = std::process::Command::new("gdalsrsinfo")
        .args(["-o", "wkt_esri", "--single-line", "EPSG:3857"])
        .output()
        .expect("gdalsrsinfo (Debian gdal-bin, installed by `make deps`) must be on PATH");
    let esri = String::from_utf8(esri.stdout).unwrap();
    assert!(esri.contains("PROJCS["), "{esri}");
    d.write("esri.prj", &esri);
    let o = d.run(&["mesh", &dem(), "-o", "esri.obj", "--max-error", "9", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read_to_string(d.path("esri.prj")).unwrap(), esri);
    // A read-only one is refused before any work, as a read-only mesh is.
    let prj = d.path("m.prj");
    let mut mode = std::fs::metadata(&prj).unwrap().permissions();
    mode.set_readonly(true);
    std::fs::set_permissions(&prj, mode).unwrap();
    let o = d.run(&["mesh", &dem(), "-o", "m.obj", "--max-error", "5"]);
    assert_fails_naming(&o, &["m.obj", "m.prj", "read-only"]);
    // A device gets no sidecar (nothing may be made in /dev by a test, so a FIFO with a
    // reader stands in for it).
    let fifo = d.path("pipe.obj");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let reader = std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap());
    let o = d.run(&["mesh", &dem(), "-o", "pipe.obj", "--max-error", "9", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let obj = reader.join().unwrap();
    assert!(obj.contains("\nv ") && obj.contains("\nf "), "{obj}");
    assert!(!d.path("pipe.prj").exists());
}

#[test]
fn small_cases_fail_early_and_clearly() {
    let d = Dir::new();
    // A trailing slash names a directory: refused before the work (it failed at the
    // final rename).
    let o = d.run(&["mesh", &dem(), "-o", "m.ply/", "--max-error", "1"]);
    assert_fails_naming(&o, &["m.ply/", "ends with '/'"]);
    // A negative count is an invalid value, not an unknown flag.
    let o = d.run(&["mesh", &dem(), "-o", "m.ply", "--max-triangles", "-5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("invalid value '-5'"), "{}", stderr(&o));
    // A FIFO with no writer: GDAL blocked for ever.
    let fifo = d.path("pipe.tif");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let o = d.run(&["info", "pipe.tif"]);
    assert_fails_naming(&o, &["pipe.tif", "not a file"]);
    std::fs::remove_file(&fifo).unwrap();
    assert!(d.files().is_empty(), "{:?}", d.files());
    // A symlink loop: one of the links was replaced by the mesh.
    std::os::unix::fs::symlink("b.ply", d.path("a.ply")).unwrap();
    std::os::unix::fs::symlink("a.ply", d.path("b.ply")).unwrap();
    let o = d.run(&["mesh", &dem(), "-o", "a.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["a.ply", "loops"]);
    for link in ["a.ply", "b.ply"] {
        let meta = std::fs::symlink_metadata(d.path(link)).unwrap();
        assert!(meta.file_type().is_symlink(), "{link}");
    }
}

#[cfg(unix)]
#[test]
fn a_replaced_output_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let d = Dir::new();
    for name in ["m.ply", "r.json"] {
        d.write(name, "old");
        std::fs::set_permissions(d.path(name), std::fs::Permissions::from_mode(0o600)).unwrap();
    }
    let o = d.run(&[
        "mesh",
        &dem(),
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--report",
        "r.json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["m.ply", "r.json"] {
        let mode = std::fs::metadata(d.path(name))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o600, "{name}");
        assert_ne!(std::fs::read(d.path(name)).unwrap(), b"old");
    }
}

#[test]
fn a_container_of_subdatasets_names_one_to_give() {
    // A GeoPackage (as a netCDF) with two rasters has no band of its own: the message said
    // "band 1 out of range, the raster has 0 band(s)".
    let d = Dir::new();
    let etopo = fixture("etopo5_2deg_i16.tif");
    for (table, extra) in [("a", None), ("b", Some("APPEND_SUBDATASET=YES"))] {
        let mut args = vec!["-q", "-of", "GPKG", &etopo, "two.gpkg"];
        let name = format!("RASTER_TABLE={table}");
        args.extend(["-co", &name]);
        if let Some(extra) = extra {
            args.extend(["-co", extra]);
        }
        let o = std::process::Command::new("gdal_translate")
            .args(&args)
            .current_dir(d.path(""))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let o = d.run(&["mesh", "two.gpkg", "-o", "m.ply", "--max-error", "10"]);
    assert_fails_naming(&o, &["two.gpkg", "2 subdataset(s)", "GPKG:two.gpkg:a"]);
    let o = d.run(&[
        "mesh",
        "GPKG:two.gpkg:b",
        "-o",
        "m.ply",
        "--max-error",
        "10",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_raster_placed_by_geolocation_arrays_says_they_are_not_used() {
    // A netCDF swath placed by geolocation arrays was meshed in pixel coordinates without a
    // word, and tiles said only "no CRS and no geotransform".
    let d = Dir::new();
    let vrt = stretched_dem(50, 40).replace(
        "<VRTRasterBand",
        "<Metadata domain=\"GEOLOCATION\"><MDI key=\"X_DATASET\">lon.tif</MDI>\
         <MDI key=\"X_BAND\">1</MDI><MDI key=\"Y_DATASET\">lat.tif</MDI>\
         <MDI key=\"Y_BAND\">1</MDI></Metadata><VRTRasterBand",
    );
    d.write("swath.vrt", &vrt);
    let o = d.run(&["mesh", "swath.vrt", "-o", "m.ply", "--max-error", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("geolocation arrays"), "{}", stderr(&o));
    let o = d.run(&["info", "swath.vrt"]);
    assert!(crate::util::stdout(&o).contains("geolocation arrays"));
    let o = d.run(&["tiles", "swath.vrt", "-o", "t"]);
    assert_fails_naming(&o, &["swath.vrt", "geolocation arrays", "gdalwarp -geoloc"]);
}

#[test]
fn verify_against_the_wrong_band_says_which_band_it_read() {
    let d = Dir::new();
    let one = stretched_dem(50, 40);
    let start = one.find("<VRTRasterBand").unwrap();
    let end = one.find("</VRTRasterBand>").unwrap() + "</VRTRasterBand>".len();
    let second = one[start..end]
        .replace("band=\"1\"", "band=\"2\"")
        .replace("<SimpleSource", "<Offset>100</Offset><SimpleSource");
    d.write(
        "two.vrt",
        &one.replace("</VRTDataset>", &format!("{second}</VRTDataset>")),
    );
    let o = d.run(&[
        "mesh",
        "two.vrt",
        "-o",
        "m.ply",
        "--max-error",
        "1",
        "--band",
        "2",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = d.run(&["verify", "two.vrt", "m.ply", "--max-error", "1"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("band 1 of 2"), "{}", stderr(&o));
    let o = d.run(&[
        "verify",
        "two.vrt",
        "m.ply",
        "--max-error",
        "1",
        "--band",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("band"), "{}", stderr(&o));
}

#[test]
fn verify_against_another_raster_on_the_same_lattice_says_it_is_not_its_mesh() {
    // A crop of the meshed DEM, as a raster of its own: its grid holds the lattice of the
    // mesh's vertices but not their extent. That was exit 1 ("max error: 0", "vertex
    // outside the grid"); like a mesh off the lattice, it is another raster's mesh: 2.
    let d = Dir::new();
    let dem = dem();
    let o = d.run(&["mesh", &dem, "-o", "m.ply", "--max-error", "1", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let info = tinsmith_raster::open_info(std::path::Path::new(&dem), 1).expect("info");
    let g = info.geo_transform.expect("a geotransform");
    let (x0, y0) = (20.0, 10.0);
    let crop = [
        g[0] + x0 * g[1] + y0 * g[2],
        g[1],
        g[2],
        g[3] + x0 * g[4] + y0 * g[5],
        g[4],
        g[5],
    ];
    d.write(
        "crop.vrt",
        &format!(
            r#"<VRTDataset rasterXSize="60" rasterYSize="50">
  <GeoTransform>{:?}, {:?}, {:?}, {:?}, {:?}, {:?}</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1">
    <NoDataValue>-3.4028234663852886e+38</NoDataValue>
    <SimpleSource>
      <SourceFilename relativeToVRT="0">{dem}</SourceFilename>
      <SourceBand>1</SourceBand>
      <SrcRect xOff="20" yOff="10" xSize="60" ySize="50"/>
      <DstRect xOff="0" yOff="0" xSize="60" ySize="50"/>
    </SimpleSource>
  </VRTRasterBand>
</VRTDataset>
"#,
            crop[0], crop[1], crop[2], crop[3], crop[4], crop[5]
        ),
    );
    for command in ["verify", "contour"] {
        let o = match command {
            "verify" => d.run(&["verify", "crop.vrt", "m.ply", "--max-error", "1"]),
            _ => d.run(&[
                "contour",
                "crop.vrt",
                "--mesh",
                "m.ply",
                "-o",
                "c.geojson",
                "--levels",
                "500",
            ]),
        };
        assert_fails_naming(&o, &["m.ply", "crop.vrt", "outside", "not of this raster"]);
    }
    assert_eq!(d.files(), vec!["crop.vrt", "m.ply"]);
}

#[test]
fn info_says_nan_samples_are_nodata_when_none_is_declared() {
    // "nodata: none" beside "(2 nodata)" read as a contradiction.
    let d = Dir::new();
    d.write(
        "nan.asc",
        "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1.5 nan 3.5\n4.5 5.5 nan\n",
    );
    let o = d.run(&["info", "nan.asc"]);
    let out = crate::util::stdout(&o);
    assert!(
        out.contains("none declared (NaN or infinite samples are nodata)"),
        "{out}"
    );
    assert!(out.contains("(2 nodata)"), "{out}");
}

#[test]
fn band_out_of_range() {
    let d = Dir::new();
    let o = d.run(&[
        "mesh",
        &dem(),
        "-o",
        "out.ply",
        "--max-error",
        "1",
        "--band",
        "2",
    ]);
    assert_fails_naming(&o, &["tintn_valid_raster_3857.tif", "band 2"]);
    assert!(d.files().is_empty());
}

#[test]
fn all_nodata() {
    let d = Dir::new();
    d.write(
        "empty.asc",
        "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n-9999 -9999 -9999\n-9999 -9999 -9999\n",
    );
    let o = d.run(&["mesh", "empty.asc", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["empty.asc", "nodata"]);
    assert_eq!(d.files(), vec!["empty.asc"]);
}

#[test]
fn no_valid_cell() {
    let d = Dir::new();
    d.write(
        "row.asc",
        "ncols 4\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 2 3 4\n-9999 -9999 -9999 -9999\n",
    );
    let o = d.run(&["mesh", "row.asc", "-o", "out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["row.asc", "2x2"]);
    assert_eq!(d.files(), vec!["row.asc"]);
}

#[test]
fn bad_max_error_values() {
    let d = Dir::new();
    // "-inf" was taken for a flag ("unexpected argument '-i'").
    for bad in ["-1", "NaN", "inf", "-inf", "abc"] {
        let o = d.run(&["mesh", &dem(), "-o", "out.ply", "--max-error", bad]);
        assert!(!o.status.success(), "--max-error {bad} accepted");
        let err = crate::util::stderr(&o);
        assert!(err.contains("--max-error"), "{err}");
        if bad != "abc" {
            assert!(err.contains("finite number"), "{err}");
        }
        assert!(d.files().is_empty());
    }
    let o = d.run(&["mesh", &dem(), "-o", "out.ply"]);
    assert!(!o.status.success());
    assert!(crate::util::stderr(&o).contains("--max-error"));
    assert!(d.files().is_empty());
}

#[test]
fn missing_output_directory() {
    let d = Dir::new();
    let o = d.run(&[
        "mesh",
        &dem(),
        "-o",
        "no/such/dir/out.ply",
        "--max-error",
        "1",
    ]);
    assert_fails_naming(&o, &["no/such/dir/out.ply", "does not exist"]);
    assert!(d.files().is_empty());
}

#[test]
fn unwritable_output_directory() {
    let d = Dir::new();
    let ro = d.path("ro");
    std::fs::create_dir(&ro).unwrap();
    let mut perms = std::fs::metadata(&ro).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut perms, 0o555);
    std::fs::set_permissions(&ro, perms).unwrap();
    // Root ignores directory permissions; a file where a directory is expected fails for
    // everyone.
    d.write("file", "");
    let o = d.run(&["mesh", &dem(), "-o", "file/out.ply", "--max-error", "1"]);
    assert_fails_naming(&o, &["file/out.ply"]);
    let is_root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .map(|o| o.stdout == b"0\n")
        .unwrap_or(false);
    if !is_root {
        let o = d.run(&["mesh", &dem(), "-o", "ro/out.ply", "--max-error", "1"]);
        assert_fails_naming(&o, &["ro/out.ply"]);
    }
    assert_eq!(std::fs::read_dir(&ro).unwrap().count(), 0);
}

#[test]
fn unknown_output_extension() {
    let d = Dir::new();
    let o = d.run(&["mesh", &dem(), "-o", "out.xyz", "--max-error", "1"]);
    assert_fails_naming(&o, &["out.xyz"]);
    assert!(d.files().is_empty());
}

#[test]
fn verify_with_a_missing_mesh() {
    let d = Dir::new();
    let o = d.run(&["verify", &dem(), "gone.ply"]);
    assert_fails_naming(&o, &["gone.ply"]);
}

#[test]
fn a_pyramid_needs_a_crs_and_the_message_names_the_file_once() {
    let d = Dir::new();
    // ESRI ASCII without a .prj: a geotransform but no CRS.
    d.write(
        "nocrs.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n7 8 9\n",
    );
    let o = d.run(&["tiles", "nocrs.asc", "-o", "pyramid", "-q"]);
    assert_fails_naming(&o, &["nocrs.asc", "no CRS"]);
    let message = crate::util::stderr(&o);
    assert_eq!(message.matches("nocrs.asc").count(), 1, "{message}");
    assert_eq!(d.files(), vec!["nocrs.asc"]);

    // Geographic, but beyond the north pole: said as such (it was "no tile with a 2x2
    // block of valid samples").
    d.write(
        "north.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 95\ncellsize 1\n1 2 3\n4 5 6\n7 8 9\n",
    );
    d.write(
        "north.prj",
        "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137,\
         298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"Degree\",0.017453292519943295]]",
    );
    let o = d.run(&["tiles", "north.asc", "-o", "pyramid", "-q"]);
    assert_fails_naming(&o, &["north.asc", "outside latitudes -90..90"]);
    assert!(!d.path("pyramid").exists());
}

#[test]
fn whole_raster_runs_on_a_raster_too_large_for_memory() {
    // A VRT that declares a 1,000,000 x 1,000,000 raster over the fixture: nothing is read,
    // and every run that needs the whole raster at once is refused up front instead of
    // being killed partway.
    let d = Dir::new();
    d.write("huge.vrt", &stretched_dem(1_000_000, 1_000_000));
    for target in ["--max-triangles", "--max-vertices"] {
        let o = d.run(&["mesh", "huge.vrt", "-o", "out.ply", target, "1000"]);
        assert_fails_naming(
            &o,
            &[
                "huge.vrt",
                "1000000x1000000",
                "GB is available",
                "--max-error",
            ],
        );
        assert_eq!(d.files(), vec!["huge.vrt"]);
    }
    // The other whole-raster runs: the full grid's contours, one huge tile, verify.
    let o = d.run(&["contour", "huge.vrt", "-o", "out.fgb", "--interval", "10"]);
    assert_fails_naming(
        &o,
        &["huge.vrt", "contouring the full grid", "--max-error > 0"],
    );
    let o = d.run(&[
        "mesh",
        "huge.vrt",
        "-o",
        "out.ply",
        "--max-error",
        "1",
        "--tile-size",
        "2000000",
    ]);
    assert_fails_naming(&o, &["huge.vrt", "one tile", "smaller --tile-size"]);
    let o = d.run(&["verify", "huge.vrt", "out.ply"]);
    assert_fails_naming(&o, &["huge.vrt", "verify needs the whole"]);
    assert_eq!(d.files(), vec!["huge.vrt"]);
}

#[cfg(unix)]
#[test]
fn output_that_is_the_input_is_refused_and_the_input_kept() {
    let d = Dir::new();
    let copy = d.path("dem.tif");
    std::fs::copy(dem(), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    std::os::unix::fs::symlink("dem.tif", d.path("alias.ply")).unwrap();
    std::os::unix::fs::symlink("dem.tif", d.path("alias.geojson")).unwrap();
    let cases: [(&[&str], &str); 4] = [
        (
            &[
                "mesh",
                "dem.tif",
                "-o",
                "dem.tif",
                "--format",
                "ply",
                "--max-error",
                "1",
            ],
            "dem.tif",
        ),
        (
            &["mesh", "dem.tif", "-o", "alias.ply", "--max-error", "1"],
            "alias.ply",
        ),
        (
            &[
                "mesh",
                "dem.tif",
                "-o",
                "m.ply",
                "--max-error",
                "1",
                "--report",
                "dem.tif",
            ],
            "dem.tif",
        ),
        (
            &[
                "contour",
                "dem.tif",
                "-o",
                "alias.geojson",
                "--interval",
                "10",
            ],
            "alias.geojson",
        ),
    ];
    for (args, named) in cases {
        let o = d.run(args);
        assert_fails_naming(&o, &[named, "input file"]);
    }
    assert_eq!(std::fs::read(&copy).unwrap(), before);
    assert!(!d.path("m.ply").exists());
}

#[test]
fn two_files_of_one_run_that_are_the_same_file_are_refused() {
    let d = Dir::new();
    let o = d.run(&["mesh", &dem(), "-o", "m.geojson", "--max-error", "1", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mesh_before = std::fs::read(d.path("m.geojson")).unwrap();
    std::os::unix::fs::symlink("m.geojson", d.path("alias.geojson")).unwrap();
    let cases: [(&[&str], [&str; 2]); 4] = [
        (
            &[
                "mesh",
                &dem(),
                "-o",
                "t.ply",
                "--max-error",
                "1",
                "--report",
                "t.ply",
            ],
            ["t.ply", "the output"],
        ),
        (
            &[
                "mesh",
                &dem(),
                "-o",
                "t.ply",
                "--max-error",
                "1",
                "--report",
                "./t.ply",
                "--tile-size",
                "16",
            ],
            ["t.ply", "the output"],
        ),
        (
            &[
                "contour",
                &dem(),
                "--mesh",
                "m.geojson",
                "-o",
                "m.geojson",
                "--interval",
                "10",
            ],
            ["m.geojson", "--mesh input"],
        ),
        (
            &[
                "contour",
                &dem(),
                "--mesh",
                "m.geojson",
                "-o",
                "alias.geojson",
                "--interval",
                "10",
            ],
            ["alias.geojson", "--mesh input"],
        ),
    ];
    for (args, named) in cases {
        let o = d.run(args);
        assert_fails_naming(&o, &named);
    }
    assert!(!d.path("t.ply").exists());
    assert_eq!(std::fs::read(d.path("m.geojson")).unwrap(), mesh_before);
}

#[test]
fn a_report_over_another_file_of_the_run_is_refused() {
    // The report replaced the OBJ's .prj, a pyramid's layer.json or a --per-tile mesh, and
    // the run exited 0.
    let d = Dir::new();
    std::fs::create_dir(d.path("pyramid")).unwrap();
    let cases: [(&[&str], [&str; 2]); 6] = [
        // The directory itself: the report's rename failed after the output was in place.
        (
            &[
                "mesh",
                &dem(),
                "--per-tile",
                "per",
                "--max-error",
                "1",
                "--tile-size",
                "64",
                "--report",
                "per",
            ],
            ["per", "--per-tile directory"],
        ),
        (
            &["tiles", &dem(), "-o", "new", "--report", "new"],
            ["new", "pyramid directory"],
        ),
        (
            &[
                "mesh",
                &dem(),
                "-o",
                "m.obj",
                "--max-error",
                "1",
                "--report",
                "m.prj",
            ],
            ["m.prj", "CRS sidecar"],
        ),
        (
            &[
                "mesh",
                &dem(),
                "-o",
                "m.obj",
                "--max-error",
                "1",
                "--report",
                "m.prj",
                "--tile-size",
                "16",
            ],
            ["m.prj", "CRS sidecar"],
        ),
        (
            &[
                "mesh",
                &dem(),
                "--per-tile",
                "per",
                "--max-error",
                "1",
                "--tile-size",
                "64",
                "--report",
                "per/tile_r0_c0.ply",
            ],
            ["per/tile_r0_c0.ply", "--per-tile directory"],
        ),
        (
            &[
                "tiles",
                &dem(),
                "-o",
                "pyramid",
                "--report",
                "pyramid/layer.json",
            ],
            ["pyramid/layer.json", "pyramid directory"],
        ),
    ];
    for (args, named) in cases {
        let o = d.run(args);
        assert_fails_naming(&o, &named);
    }
    assert_eq!(d.files(), vec!["pyramid"]);
    assert_eq!(std::fs::read_dir(d.path("pyramid")).unwrap().count(), 0);
}

#[cfg(unix)]
#[test]
fn an_output_at_a_symbolic_link_is_refused_file_or_directory() {
    // `-o` through a link once replaced the file it pointed to, wherever that was, while
    // `tiles` refused a linked directory: every output at a link is refused now.
    let d = Dir::new();
    d.write("real.ply", "old");
    std::os::unix::fs::symlink("real.ply", d.path("link.ply")).unwrap();
    std::fs::create_dir(d.path("real")).unwrap();
    std::os::unix::fs::symlink("real", d.path("linked")).unwrap();
    std::os::unix::fs::symlink("real.ply", d.path("r.json")).unwrap();
    std::os::unix::fs::symlink("real.ply", d.path("lines.geojson")).unwrap();
    let dem = dem();
    for (args, named) in [
        (
            vec!["mesh", &dem, "-o", "link.ply", "--max-error", "1"],
            "link.ply",
        ),
        (
            vec!["contour", &dem, "-o", "lines.geojson", "--levels", "500"],
            "lines.geojson",
        ),
        (vec!["tiles", &dem, "-o", "linked"], "linked"),
        (
            vec![
                "mesh",
                &dem,
                "-o",
                "m.ply",
                "--max-error",
                "1",
                "--report",
                "r.json",
            ],
            "r.json",
        ),
    ] {
        let o = d.run(&args);
        assert_fails_naming(&o, &[named, "symbolic link"]);
    }
    assert_eq!(std::fs::read(d.path("real.ply")).unwrap(), b"old");
    assert!(std::fs::read_dir(d.path("real")).unwrap().next().is_none());
    assert_eq!(
        d.files(),
        vec![
            "lines.geojson",
            "link.ply",
            "linked",
            "r.json",
            "real",
            "real.ply"
        ]
    );
}

#[test]
fn options_that_would_be_ignored_are_refused() {
    let d = Dir::new();
    let dem = dem();
    for (args, named) in [
        (
            &[
                "mesh",
                &dem,
                "-o",
                "m.ply",
                "--max-error",
                "1",
                "--tile-format",
                "obj",
            ][..],
            "--tile-format",
        ),
        (
            &[
                "mesh",
                &dem,
                "-o",
                "m.ply",
                "--max-triangles",
                "100",
                "--flip-rounds",
                "2",
            ],
            "--flip-rounds",
        ),
        (
            &[
                "mesh",
                &dem,
                "-o",
                "m.ply",
                "--max-vertices",
                "100",
                "--extend-rounds",
                "1",
            ],
            "--extend-rounds",
        ),
    ] {
        let o = d.run(args);
        assert_fails_naming(&o, &[named]);
        assert!(d.files().is_empty(), "{:?}", d.files());
    }
}

#[test]
fn an_unreachable_count_is_noted() {
    let d = Dir::new();
    let o = d.run(&["mesh", &dem(), "-o", "m.ply", "--max-triangles", "1"]);
    assert!(o.status.success());
    let err = crate::util::stderr(&o);
    assert!(err.contains("is above --max-triangles 1"), "{err}");
    let o = d.run(&[
        "mesh",
        &dem(),
        "-o",
        "m.ply",
        "--max-triangles",
        "10",
        "--max-error",
        "0.01",
    ]);
    assert!(o.status.success());
    let err = crate::util::stderr(&o);
    assert!(
        err.contains("--max-error 0.01 stopped the decimation first"),
        "{err}"
    );
}

#[test]
fn a_pyramid_is_written_whole_or_not_at_all() {
    let d = Dir::new();
    // Every sample nodata: nothing to write, so no directory and no layer.json.
    d.write(
        "empty.asc",
        "ncols 3\nnrows 3\nxllcorner 7\nyllcorner 46\ncellsize 0.01\nNODATA_value -9999\n\
         -9999 -9999 -9999\n-9999 -9999 -9999\n-9999 -9999 -9999\n",
    );
    d.write(
        "empty.prj",
        "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],\
         PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]",
    );
    let o = d.run(&["tiles", "empty.asc", "-o", "pyramid", "-q"]);
    assert_fails_naming(&o, &["empty.asc"]);
    assert_eq!(d.files(), vec!["empty.asc", "empty.prj"]);

    // Heights beyond what quantized-mesh's f32 height range can hold.
    d.write(
        "huge.asc",
        "ncols 3\nnrows 3\nxllcorner 7\nyllcorner 46\ncellsize 0.01\n\
         3.0e38 -3.0e38 3.0e38\n-3.0e38 3.0e38 -3.0e38\n3.0e38 -3.0e38 3.0e38\n",
    );
    std::fs::copy(d.path("empty.prj"), d.path("huge.prj")).unwrap();
    let o = d.run(&["tiles", "huge.asc", "-o", "pyramid", "-q"]);
    assert_fails_naming(&o, &["huge.asc", "quantized-mesh"]);
    assert!(!d.path("pyramid").exists());
    // Float64 heights beyond f32 altogether (clamped by the warp): the source's named.
    d.write(
        "beyond.asc",
        "ncols 3\nnrows 3\nxllcorner 7\nyllcorner 46\ncellsize 0.01\n\
         1e300 1e300 1e300\n1 2 3\n4 5 6\n",
    );
    std::fs::copy(d.path("empty.prj"), d.path("beyond.prj")).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(["tiles", "beyond.asc", "-o", "pyramid", "-q"])
        .current_dir(d.path(""))
        .env("AAIGRID_DATATYPE", "Float64") // GDAL reads the grid as Float64
        .output()
        .expect("run tinsmith");
    assert_fails_naming(
        &o,
        &[
            "beyond.asc",
            "heights up to 1e300 in magnitude",
            "quantized-mesh",
        ],
    );
    assert!(!d.path("pyramid").exists());

    // A directory that holds other files is never written into.
    std::fs::create_dir(d.path("taken")).unwrap();
    std::fs::write(d.path("taken/keep.txt"), "mine").unwrap();
    let o = d.run(&["tiles", &dem(), "-o", "taken", "-q"]);
    assert_fails_naming(&o, &["taken", "not an empty directory"]);
    let left: Vec<_> = std::fs::read_dir(d.path("taken")).unwrap().collect();
    assert_eq!(left.len(), 1);
    // Nor a file in its place (said as such).
    std::fs::write(d.path("afile"), "mine").unwrap();
    let o = d.run(&["tiles", &dem(), "-o", "afile", "-q"]);
    assert_fails_naming(&o, &["afile", "exists and is not a directory"]);
    assert_eq!(std::fs::read(d.path("afile")).unwrap(), b"mine");
    // Nor under a file.
    let o = d.run(&["tiles", &dem(), "-o", "afile/sub", "-q"]);
    assert_fails_naming(&o, &["afile/sub", "afile is a file"]);
    assert_eq!(std::fs::read(d.path("afile")).unwrap(), b"mine");

    // An empty directory (or a missing one, parents included) gets the whole pyramid.
    std::fs::create_dir(d.path("ready")).unwrap();
    for out in ["ready", "new/parent/pyramid"] {
        let o = d.run(&["tiles", &dem(), "-o", out, "-q"]);
        assert!(o.status.success(), "{}", crate::util::stderr(&o));
        assert!(d.path(out).join("layer.json").is_file());
    }
    let hidden: Vec<_> = std::fs::read_dir(d.path(""))
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".tinsmith-"))
        .collect();
    assert!(hidden.is_empty(), "temporary directories left: {hidden:?}");
}

#[cfg(unix)]
#[test]
fn an_interrupted_run_leaves_no_temporary_file() {
    let d = Dir::new();
    // The fixture stretched 30 times and meshed at a zero bound: 12.8 M triangles, seconds
    // of work with temporary files open most of the time.
    d.write("big.vrt", &stretched_dem(3000, 2400));
    // Exit codes as a shell reports a process the signal ended: 128 + its number.
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(["mesh", "big.vrt", "-o", "out.ply", "--max-error", "0", "-q"])
            .current_dir(d.path(""))
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start tinsmith");
        let temporary = || d.files().iter().any(|f| f.starts_with(".tinsmith-"));
        let started = std::time::Instant::now();
        while !temporary() {
            assert!(
                child.try_wait().unwrap().is_none(),
                "finished before any temporary file was seen"
            );
            // The mesh's temporary file is made when writing starts, after the whole
            // decimation: minutes on a loaded CI machine (120 s was once not enough for
            // the same run in the killed-run test).
            assert!(started.elapsed().as_secs() < 900, "no temporary file");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let killed = std::process::Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .expect("kill");
        assert!(killed.success());
        let out = child.wait_with_output().expect("wait");
        assert_eq!(
            out.status.code(),
            Some(code),
            "SIG{signal}: {:?}: {}",
            out.status,
            crate::util::stderr(&out)
        );
        assert!(crate::util::stderr(&out).contains("interrupted"));
        assert_eq!(d.files(), vec!["big.vrt"], "SIG{signal}");
    }
}

#[cfg(unix)]
#[test]
fn an_interrupt_after_the_first_output_is_in_place_completes_the_run() {
    // One rule for every command and output: a signal before the first output is renamed
    // into place cancels the run and leaves every old output; after it, the run puts the
    // rest in place and exits 0. The hook sends the signal just after that first rename
    // (the mesh, or an OBJ's .prj sidecar, or the pyramid), when the report is still old.
    let d = Dir::new();
    for (signal, args) in [
        ("2", ["mesh", "-o", "out.ply", "--max-error", "1"]),
        ("15", ["mesh", "-o", "out.obj", "--max-error", "1"]),
        ("2", ["tiles", "-o", "terrain", "--band", "1"]),
    ] {
        let output = args[2];
        if args[0] == "mesh" {
            d.write(output, "old");
        }
        d.write("r.json", "old");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args([args[0], &dem()])
            .args(&args[1..])
            .args(["--report", "r.json", "-q"])
            .env("TINSMITH_TEST_SIGNAL_AFTER_PLACING", signal)
            .current_dir(d.path(""))
            .output()
            .expect("run tinsmith");
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("interrupted"), "{err}");
        let report = std::fs::read_to_string(d.path("r.json")).unwrap();
        assert!(
            report.starts_with('{'),
            "{args:?}: the report is still the old one"
        );
        let written = d.path(output);
        assert!(written.is_dir() || std::fs::read(&written).unwrap() != b"old");
        let left: Vec<String> = d
            .files()
            .into_iter()
            .filter(|f| f.starts_with(".tinsmith-"))
            .collect();
        assert!(left.is_empty(), "{args:?}: {left:?}");
    }
}

#[cfg(unix)]
#[test]
fn a_killed_runs_temporary_file_is_removed_by_the_next_run_there() {
    // SIGKILL (the out-of-memory killer) gives no chance to clean up: the temporary file
    // stays, and the next run writing in that directory removes it once it is a minute
    // old (its lock died with the process). A young one may be a live run's: it stays.
    let d = Dir::new();
    d.write("big.vrt", &stretched_dem(3000, 2400));
    // The report's temporary file is made before the raster is read: it is there at once,
    // however slowly a loaded machine gets to the mesh's.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(["mesh", "big.vrt", "-o", "out.ply", "--max-error", "0", "-q"])
        .args(["--report", "r.json"])
        .current_dir(d.path(""))
        .spawn()
        .expect("start tinsmith");
    let temporaries = || -> Vec<String> {
        d.files()
            .into_iter()
            .filter(|f| f.starts_with(".tinsmith-"))
            .collect()
    };
    let started = std::time::Instant::now();
    while temporaries().is_empty() {
        assert!(child.try_wait().unwrap().is_none(), "finished too soon");
        assert!(started.elapsed().as_secs() < 120, "no temporary file");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().expect("SIGKILL");
    child.wait().expect("wait");
    let left = temporaries();
    assert!(!left.is_empty() && left.len() <= 2, "{left:?}");
    let two_hours_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(7200);
    for name in &left {
        std::fs::File::options()
            .write(true)
            .open(d.path(name))
            .and_then(|f| f.set_modified(two_hours_ago))
            .expect("age the left file");
    }
    d.write(".tinsmith-young1.tmp", "x");

    let o = d.run(&["mesh", &dem(), "--max-error", "2", "-o", "m.ply"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let removed = format!(
        "removed {} temporary output(s) that killed runs left behind",
        left.len()
    );
    assert!(
        err.contains(&removed) && left.iter().all(|name| err.contains(name.as_str())),
        "{err}"
    );
    assert_eq!(
        d.files(),
        vec![".tinsmith-young1.tmp", "big.vrt", "m.ply"],
        "{err}"
    );
}

#[test]
fn info_and_verify_end_quietly_when_stdout_is_closed() {
    // `tinsmith verify ... | head -1`: the reader is gone before the report is printed.
    let d = Dir::new();
    let o = d.run(&["mesh", &dem(), "--max-error", "2", "-o", "m.ply", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = d.path("m.ply");
    for args in [
        vec!["info", &dem()],
        vec!["verify", &dem(), m.to_str().unwrap()],
    ] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(&args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run tinsmith");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("wait");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn commands_that_write_files_finish_when_stderr_is_closed() {
    // `tinsmith mesh ... 2>&1 | head -1`: the summary goes to a closed pipe. It used to
    // panic (exit 101); the file is the result, the notes are not.
    let d = Dir::new();
    for (args, output) in [
        (
            vec!["mesh", &dem(), "--max-error", "2", "-o", "m.ply"],
            "m.ply",
        ),
        (
            vec!["contour", &dem(), "--interval", "100", "-o", "c.geojson"],
            "c.geojson",
        ),
    ] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(&args)
            .current_dir(d.path("."))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run tinsmith");
        drop(child.stderr.take());
        let status = child.wait().expect("wait");
        assert!(status.success(), "{args:?}: {status}");
        assert!(d.path(output).exists(), "{args:?}: no {output}");
    }
}

#[test]
fn a_read_only_output_is_not_replaced() {
    // Writing renames a new file over the output, which the directory allows whatever the
    // file's mode: a mesh, lines or report made read-only used to be replaced silently.
    use std::os::unix::fs::PermissionsExt;
    let d = Dir::new();
    for name in ["kept.ply", "kept.geojson", "kept.json"] {
        let p = d.write(name, "precious");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).unwrap();
    }
    let dem = dem();
    let runs: [&[&str]; 3] = [
        &["mesh", &dem, "-o", "kept.ply", "--max-error", "5"],
        &["contour", &dem, "-o", "kept.geojson", "--interval", "50"],
        &[
            "mesh",
            &dem,
            "-o",
            "new.ply",
            "--max-error",
            "5",
            "--report",
            "kept.json",
        ],
    ];
    for (args, name) in runs.iter().zip(["kept.ply", "kept.geojson", "kept.json"]) {
        let o = d.run(args);
        assert_fails_naming(&o, &[name, "read-only"]);
        assert_eq!(std::fs::read_to_string(d.path(name)).unwrap(), "precious");
    }
    assert_eq!(d.files(), vec!["kept.geojson", "kept.json", "kept.ply"]);
}

#[test]
fn heights_beyond_1e37_are_refused_with_one_message() {
    // The refusal came after a note that the heights left decimation 0 of the bound.
    let d = Dir::new();
    d.write(
        "huge.asc",
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 2e37 6\n7 8 9\n",
    );
    // The float32 formats said first that float32 rounds such heights beyond the bound.
    for out in ["m.ply", "m.glb", "m.stl"] {
        let o = d.run(&["mesh", "huge.asc", "-o", out, "--max-error", "1"]);
        assert_fails_naming(&o, &["huge.asc", "1e37"]);
        assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
        assert_eq!(d.files(), vec!["huge.asc"]);
    }
    // Tiled, with the huge sample in the last of 4 tiles: refused before any tile, so no
    // tile is named (the first tile was, though its heights were fine).
    let rows: String = (0..5)
        .map(|y| {
            let row: Vec<&str> = (0..5)
                .map(|x| if (x, y) == (4, 4) { "2e37" } else { "1" })
                .collect();
            row.join(" ") + "\n"
        })
        .collect();
    d.write(
        "late.asc",
        &format!("ncols 5\nnrows 5\nxllcorner 0\nyllcorner 0\ncellsize 1\n{rows}"),
    );
    let o = d.run(&[
        "mesh",
        "late.asc",
        "-o",
        "m.glb",
        "--max-error",
        "1",
        "--tile-size",
        "3",
    ]);
    assert_fails_naming(&o, &["late.asc", "1e37"]);
    assert!(!stderr(&o).contains("tile"), "{}", stderr(&o));
    assert_eq!(d.files(), vec!["huge.asc", "late.asc"]);
}

#[test]
fn a_spike_too_tall_for_a_tiles_heights_is_named_whatever_its_height() {
    // Flat ground at 3" with one spike: a spike of 1e9 was said to span more than a
    // tile's heights hold; one of 1e12 failed first in the border's rule ("border sample
    // (91, 0) cannot be removed: skipping it exceeds the error bound").
    let d = Dir::new();
    for spike in ["1e9", "1e12", "1e20"] {
        let rows: String = (0..200)
            .map(|y| {
                let row: Vec<&str> = (0..200)
                    .map(|x| if (x, y) == (100, 100) { spike } else { "100" })
                    .collect();
                row.join(" ") + "\n"
            })
            .collect();
        d.write(
            "spike.asc",
            &format!(
                "ncols 200\nnrows 200\nxllcorner -97.485\nyllcorner 32.655\n\
                 cellsize 0.00083333333333333\n{rows}"
            ),
        );
        let status = std::process::Command::new("gdal_translate")
            .args([
                "-q",
                "-a_srs",
                "EPSG:4326",
                "-ot",
                "Float32",
                "spike.asc",
                "spike.tif",
            ])
            .current_dir(d.path(""))
            .status()
            .expect("gdal_translate runs");
        assert!(status.success());
        let o = d.run(&["tiles", "spike.tif", "-o", "p", "-q"]);
        assert_fails_naming(&o, &["spike.tif", "span more than"]);
        assert!(!d.path("p").exists(), "{spike}: output left behind");
    }
}

#[test]
fn a_pipe_closed_early_ends_the_run_quietly_with_141() {
    // The reader of `-o /dev/stdout` stops after a few bytes: exit 128 + SIGPIPE, as a
    // shell reports it, in every writer (FlatGeobuf's error hid the broken pipe: exit 2
    // with a message; the others exited 0 as if the file had been written).
    use std::io::Read;
    let d = Dir::new();
    for (format, tile_size) in [
        ("obj", "64"),
        ("ply", "64"),
        ("ply", "1000"),
        ("geojson", "1000"),
        ("fgb", "1000"),
    ] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(["mesh", &dem(), "-o", "/dev/stdout", "--format", format])
            .args(["--max-error", "0", "-q", "--tile-size", tile_size])
            .current_dir(d.path(""))
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdout = child.stdout.take().unwrap();
        let mut first = [0u8; 16];
        stdout.read_exact(&mut first).unwrap();
        drop(stdout);
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(141), "{format}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{format}");
    }
    // Standard output redirected to a file is written in place: no temporary file or
    // rename in the file's directory, and no `.prj` beside /dev/stdout.
    for (format, tile_size) in [("obj", "64"), ("stl", "1000")] {
        let name = format!("v.{format}");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(["mesh", &dem(), "-o", "/dev/stdout", "--format", format])
            .args(["--max-error", "5", "-q", "--tile-size", tile_size])
            .current_dir(d.path(""))
            .stdout(std::fs::File::create(d.path(&name)).unwrap())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(!std::path::Path::new("/dev/stdout.prj").exists());
        let len = std::fs::metadata(d.path(&name)).unwrap().len();
        assert!(len >= 134, "{name}: {len} bytes, {}", stderr(&o));
    }
    assert_eq!(d.files(), vec!["v.obj", "v.stl"]);
}

#[test]
fn a_mesh_read_from_a_pipe_is_read_whole() {
    // PLY, STL and glTF readers check their header counts against the file's length: a
    // pipe's length (0) made every one "truncated".
    let d = Dir::new();
    for format in ["ply", "stl", "glb"] {
        let name = format!("m.{format}");
        let o = d.run(&["mesh", &dem(), "-o", &name, "--max-error", "5", "-q"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(["verify", &dem(), "/dev/stdin", "--format", format])
            .args(["--max-error", "5"])
            .current_dir(d.path(""))
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .and_then(|mut child| {
                let bytes = std::fs::read(d.path(&name))?;
                let mut stdin = child.stdin.take().expect("stdin");
                std::thread::spawn(move || std::io::Write::write_all(&mut stdin, &bytes));
                child.wait_with_output()
            })
            .unwrap();
        assert!(o.status.success(), "{format}: {}", stderr(&o));
    }
}

#[test]
fn a_report_that_cannot_be_written_stops_the_run_before_the_outputs() {
    // The report is moved into place after the mesh: a report name too long for the file
    // system failed there, with the old mesh already replaced.
    let d = Dir::new();
    d.write("y.ply", "OLD");
    let long = format!("{}.json", "b".repeat(252));
    let o = d.run(&[
        "mesh",
        &dem(),
        "-o",
        "y.ply",
        "--report",
        &long,
        "--max-error",
        "5",
    ]);
    assert_fails_naming(&o, &[&long, "too long"]);
    assert_eq!(std::fs::read_to_string(d.path("y.ply")).unwrap(), "OLD");
    assert_eq!(d.files(), vec!["y.ply"]);
}

#[cfg(unix)]
#[test]
fn an_output_name_that_is_not_utf8_is_reported_as_well_as_it_can_be() {
    // serde refused the path in the report, after the mesh was written: exit 2, no report.
    use std::os::unix::ffi::OsStrExt;
    let d = Dir::new();
    let name = std::ffi::OsStr::from_bytes(b"m\xe9sh.ply");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args([
            std::ffi::OsStr::new("mesh"),
            dem().as_ref(),
            "-o".as_ref(),
            name,
        ])
        .args(["--report", "r.json", "--max-error", "5", "-q"])
        .current_dir(d.path(""))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let report = std::fs::read_to_string(d.path("r.json")).unwrap();
    assert!(
        report.contains("\"output\": \"m\u{fffd}sh.ply\""),
        "{report}"
    );
}

#[test]
fn verify_refuses_a_raster_with_nothing_to_measure() {
    // One row of samples has no valid cell: `mesh` refuses it, and an empty mesh passed
    // `verify` with "max error: 0" though no sample was measured.
    let d = Dir::new();
    let asc = d.write(
        "row.asc",
        "ncols 5\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n1 2 3 4 5\n",
    );
    d.write("empty.obj", "# no vertices\n");
    let o = d.run(&[
        "verify",
        asc.to_str().unwrap(),
        "empty.obj",
        "--max-error",
        "0",
    ]);
    assert_fails_naming(&o, &["row.asc", "no valid cell", "nothing to measure"]);
}
