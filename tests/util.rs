//! Helpers to run the real `tinsmith` binary in a temporary directory.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A temporary directory to run one test in.
pub struct Dir {
    pub tmp: tempfile::TempDir,
}

impl Dir {
    pub fn new() -> Dir {
        Dir {
            tmp: tempfile::tempdir().expect("temp dir"),
        }
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.tmp.path().join(name)
    }

    /// Runs `tinsmith args...` in this directory.
    pub fn run(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_tinsmith"))
            .args(args)
            .current_dir(self.tmp.path())
            .output()
            .expect("run tinsmith")
    }

    /// Files in the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(self.tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    pub fn write(&self, name: &str, contents: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, contents).unwrap();
        p
    }
}

/// A committed fixture, by file name.
pub fn fixture(name: &str) -> String {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["tests/fixtures", "crates/raster/tests/fixtures", "data"] {
        let p = base.join(dir).join(name);
        if p.exists() {
            return p.to_string_lossy().into_owned();
        }
    }
    panic!("fixture {name} is missing");
}

/// Runs tinsmith with `args` in `dir` under `ulimit -v kib` (the address space limit a
/// container or a user may set).
pub fn run_under_ulimit(dir: &Dir, kib: u32, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_tinsmith"))
        .args(args)
        .current_dir(dir.path(""))
        .output()
        .expect("sh runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts a clean failure: non-zero exit, a single-line message naming `names`.
pub fn assert_fails_naming(o: &Output, names: &[&str]) {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    for n in names {
        assert!(err.contains(n), "stderr should name {n:?}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// GDAL's `gdaltransform` (Debian gdal-bin, installed by `make deps`): `points` from the
/// CRS `from` to `to` (e.g. "EPSG:4326", longitude, latitude), heights unchanged.
pub fn gdaltransform(from: &str, to: &str, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let text: String = points
        .iter()
        .map(|v| format!("{:?} {:?} {:?}\n", v[0], v[1], v[2]))
        .collect();
    let mut child = Command::new("gdaltransform")
        .args(["-s_srs", from, "-t_srs", to])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("gdaltransform (Debian gdal-bin, installed by `make deps`) must be on PATH");
    // Fed from a thread: gdaltransform answers line by line, so a large input written
    // before reading would fill both pipes.
    let mut stdin = child.stdin.take().expect("stdin");
    let feeder = std::thread::spawn(move || std::io::Write::write_all(&mut stdin, text.as_bytes()));
    let out = child.wait_with_output().expect("gdaltransform output");
    feeder.join().expect("feeder").expect("feed gdaltransform");
    let transformed: Vec<[f64; 3]> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: Vec<f64> = l
                .split_ascii_whitespace()
                .map(|c| c.parse().expect("number"))
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(transformed.len(), points.len(), "gdaltransform output");
    transformed
}

/// The ETOPO fixture warped (bilinear) into `dir/name` in Antarctic polar stereographic
/// (EPSG:3031) over x in -1000 .. 1000 km and y from -1000 km to `north` metres, 200
/// columns by `rows`; returns its path. With `north` past 0 the pole is inside.
pub fn south_polar_fixture(dir: &Dir, name: &str, north: &str, rows: &str) -> String {
    let out = dir.path(name);
    let status = Command::new("gdalwarp")
        .args([
            "-q",
            "-t_srs",
            "EPSG:3031",
            "-te",
            "-1000000",
            "-1000000",
            "1000000",
        ])
        .args([north, "-ts", "200", rows, "-r", "bilinear"])
        .arg(fixture("etopo5_2deg_i16.tif"))
        .arg(&out)
        .status()
        .expect("gdalwarp (Debian gdal-bin, installed by `make deps`) must be on PATH");
    assert!(status.success());
    out.to_string_lossy().into_owned()
}

/// A `tinsmith serve` process, killed when the test ends, however it ends (a failed
/// assertion must not leave it waiting for requests, holding the test's output open).
pub struct Server(pub std::process::Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `tinsmith serve ARGS...` in `dir` on a free port; returns the server and the
/// base URL it printed (`http://127.0.0.1:PORT/`).
pub fn serve(dir: &Dir, args: &[&str]) -> (Server, String) {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .arg("serve")
        .args(args)
        .args(["--port", "0"])
        .current_dir(dir.tmp.path())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("tinsmith serve starts");
    let stdout = child.stdout.take().expect("piped stdout");
    let server = Server(child);
    let mut line = String::new();
    std::io::BufReader::new(stdout)
        .read_line(&mut line)
        .expect("the address line");
    let base = line
        .trim()
        .rsplit(' ')
        .next()
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    (server, base)
}

/// The port of a base URL `http://127.0.0.1:PORT/`.
pub fn port_of(base: &str) -> u16 {
    base.trim_end_matches('/')
        .rsplit(':')
        .next()
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no port in {base:?}"))
}

/// Copies the directory pyramid at `dir` (`{z}/{x}/{y}.terrain`, `layer.json`) into a new
/// MBTiles file at `out` through `tinsmith_store::MbtilesStore`, each tile labelled with
/// `encoding` (as `tinsmith tiles` made them: gzipped unless `--no-gzip`). Returns the
/// number of tiles copied.
pub fn pack_mbtiles(dir: &Path, out: &Path, encoding: tinsmith_store::TileEncoding) -> usize {
    use tinsmith_store::TileStore;
    let store = tinsmith_store::MbtilesStore::create(out).expect("create the MBTiles file");
    let mut count = 0;
    for (z, x, y, path) in pyramid_tiles(dir) {
        let bytes = std::fs::read(path).expect("read a tile");
        store
            .put_tile(z, x, y, &bytes, encoding)
            .expect("put a tile");
        count += 1;
    }
    let layer = std::fs::read(dir.join("layer.json")).expect("layer.json");
    store
        .put_file("layer.json", &layer)
        .expect("put layer.json");
    store.commit().expect("commit the MBTiles file");
    count
}

/// The tiles of the directory pyramid at `dir`: (z, x, y, path), sorted.
pub fn pyramid_tiles(dir: &Path) -> Vec<(u8, u32, u32, PathBuf)> {
    let number = |p: &Path| -> Option<u32> { p.file_stem()?.to_str()?.parse().ok() };
    let entries = |d: &Path| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(d)
            .expect("read a pyramid directory")
            .map(|e| e.expect("entry").path())
            .collect();
        v.sort();
        v
    };
    let mut tiles = Vec::new();
    for zd in entries(dir).into_iter().filter(|p| p.is_dir()) {
        let Some(z) = number(&zd) else { continue };
        for xd in entries(&zd).into_iter().filter(|p| p.is_dir()) {
            let x = number(&xd).expect("a column directory");
            for tile in entries(&xd) {
                assert_eq!(tile.extension().and_then(|e| e.to_str()), Some("terrain"));
                let y = number(&tile).expect("a tile file");
                tiles.push((z as u8, x, y, tile));
            }
        }
    }
    tiles.sort();
    tiles
}

/// The Python of `.venv` (or `TINSMITH_PYTHON`), where `make deps` installs the oracles;
/// fails the test, saying how to get it, when it is missing.
pub fn venv_python() -> PathBuf {
    let path = std::env::var_os("TINSMITH_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python3"));
    assert!(
        path.exists(),
        "oracle missing: {}; run `make deps`",
        path.display()
    );
    path
}
