//! MBTiles pyramids: the file `tinsmith_store::MbtilesStore` writes, read back by an
//! independent reader (Python's `sqlite3`, with its own SQLite), and the binary that links
//! the bundled SQLite beside GDAL's.

use std::path::Path;
use std::process::Command;

use serde_json::Value;
use tinsmith_store::TileEncoding;

use crate::util::{fixture, pack_mbtiles, pyramid_tiles, stderr, Dir};

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn python_sqlite3_reads_the_directory_pyramid_back() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    let o = dir.run(&["tiles", &input, "-o", "pyramid", "--max-zoom", "12"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let tiles = pyramid_tiles(&dir.path("pyramid"));
    let file = dir.path("pyramid.mbtiles");
    assert_eq!(
        pack_mbtiles(&dir.path("pyramid"), &file, TileEncoding::Gzip),
        tiles.len()
    );
    let before = std::fs::read(&file).unwrap();

    let out = Command::new(crate::util::venv_python())
        .arg(repo().join("tests/oracles/mbtiles_read.py"))
        .arg(&file)
        .output()
        .expect("python runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let read: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        std::fs::read(&file).unwrap(),
        before,
        "reading changed the file"
    );

    // The MBTiles 1.3 schema, its indexes and its application id ("MPBX").
    assert_eq!(read["integrity"], "ok");
    assert_eq!(read["application_id"], 0x4d50_4258);
    assert_eq!(
        read["tables"],
        serde_json::json!({
            "metadata": [["name", "TEXT"], ["value", "TEXT"]],
            "tiles": [["zoom_level", "INTEGER"], ["tile_column", "INTEGER"],
                      ["tile_row", "INTEGER"], ["tile_data", "BLOB"]],
        })
    );
    assert_eq!(
        read["indexes"]["tiles"],
        serde_json::json!([{"name": "tile_index", "unique": true,
                            "columns": ["zoom_level", "tile_column", "tile_row"]}])
    );
    assert_eq!(
        read["indexes"]["metadata"],
        serde_json::json!([{"name": "name", "unique": true, "columns": ["name"]}])
    );

    // The metadata rows, from the pyramid's layer.json.
    let layer_text = std::fs::read_to_string(dir.path("pyramid/layer.json")).unwrap();
    let layer: Value = serde_json::from_str(&layer_text).unwrap();
    let meta = &read["metadata"];
    assert_eq!(meta["format"], "application/vnd.quantized-mesh");
    assert_eq!(meta["name"], "pyramid");
    assert_eq!(meta["json"], layer_text.as_str());
    assert_eq!(meta["content_encoding"], "gzip");
    let min_zoom = tiles.iter().map(|t| t.0).min().unwrap();
    assert_eq!(meta["minzoom"], min_zoom.to_string().as_str());
    assert_eq!(meta["maxzoom"], layer["maxzoom"].to_string().as_str());
    let bounds: Vec<f64> = meta["bounds"]
        .as_str()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let layer_bounds: Vec<f64> = layer["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(bounds, layer_bounds);
    assert_eq!(read["metadata_rows"], 7, "{meta}");

    // Every tile, at its TMS row (the pyramid's y), with the bytes of its file.
    let want: Vec<Value> = tiles
        .iter()
        .map(|(z, x, y, path)| serde_json::json!([z, x, y, hex(&std::fs::read(path).unwrap())]))
        .collect();
    assert_eq!(read["tiles"].as_array().unwrap().len(), tiles.len());
    assert_eq!(read["tiles"], Value::Array(want));
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn tiles_writes_an_mbtiles_file_holding_the_directory_pyramid() {
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    for out in ["pyramid", "terrain.mbtiles"] {
        let o = dir.run(&["tiles", &input, "-o", out, "--normals", "-q"]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let out = Command::new(crate::util::venv_python())
        .arg(repo().join("tests/oracles/mbtiles_read.py"))
        .arg(dir.path("terrain.mbtiles"))
        .output()
        .expect("python runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let read: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(read["integrity"], "ok");
    let layer_text = std::fs::read_to_string(dir.path("pyramid/layer.json")).unwrap();
    // The layer is named after the input, whatever the output.
    assert_eq!(read["metadata"]["json"], layer_text.as_str());
    let tiles = pyramid_tiles(&dir.path("pyramid"));
    let want: Vec<Value> = tiles
        .iter()
        .map(|(z, x, y, path)| serde_json::json!([z, x, y, hex(&std::fs::read(path).unwrap())]))
        .collect();
    assert!(want.len() > 20);
    assert_eq!(read["tiles"], Value::Array(want));
    // Written whole: no temporary left beside it, and shards refuse one file.
    assert_eq!(dir.files().iter().filter(|f| f.contains(".tmp")).count(), 0);
    let o = dir.run(&["tiles", &input, "-o", "s.mbtiles", "--shard", "0/2"]);
    assert!(!o.status.success() && stderr(&o).contains("directory or a bucket"));
    assert!(!dir.path("s.mbtiles").exists());
}

#[test]
fn the_binary_exports_no_sqlite_function() {
    // GDAL, PROJ and SpatiaLite call the system's libsqlite3; had the binary exported the
    // bundled copy's functions, some of their calls would bind to it (see
    // .cargo/config.toml).
    let out = Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(env!("CARGO_BIN_EXE_tinsmith"))
        .output()
        .expect("nm (binutils) runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let exported = String::from_utf8_lossy(&out.stdout);
    let sqlite: Vec<&str> = exported
        .lines()
        .filter(|l| {
            l.split_whitespace()
                .last()
                .is_some_and(|s| s.starts_with("sqlite3"))
        })
        .collect();
    assert!(sqlite.is_empty(), "exported: {sqlite:?}");
    // The bundled copy is there all the same (hidden, for tinsmith-store alone).
    let all = Command::new("nm")
        .arg(env!("CARGO_BIN_EXE_tinsmith"))
        .output()
        .expect("nm runs");
    assert!(String::from_utf8_lossy(&all.stdout).contains(" sqlite3_open_v2"));
}
