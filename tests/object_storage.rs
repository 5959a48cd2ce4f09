//! Object storage against a real S3 server on the loopback: moto's standalone server
//! (PyPI, installed by `make deps` into .venv), one per test, killed when the test ends.
//! What the store writes is read back by an independent client (boto3,
//! `tests/oracles/s3_objects.py`), and GDAL reads an input raster from the server
//! (`/vsis3/`) for the `tinsmith` binary. `#[ignore]`d so that `cargo test` passes without
//! the oracles; `make test` runs them, and a missing moto fails them.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde_json::Value;
use tinsmith_store::{BucketStore, StoreError, TileEncoding, TileStore};

use crate::util::{assert_fails_naming, fixture, stderr, stdout, Dir};

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A moto S3 server on 127.0.0.1 (a port the system chose), killed when dropped, however
/// the test ends.
struct Moto {
    child: Child,
    /// `http://127.0.0.1:PORT` (`https://` with TLS).
    endpoint: String,
}

impl Moto {
    /// Starts the server (with a self-signed certificate when `tls`) and waits until it
    /// listens. Fails the test when moto is missing.
    fn start(tls: bool) -> Moto {
        let bin = repo().join(".venv/bin/moto_server");
        assert!(
            bin.exists(),
            "oracle missing: {} (moto[server]); run `make deps`",
            bin.display()
        );
        let mut command = Command::new(&bin);
        command.args(["-H", "127.0.0.1", "-p", "0"]);
        if tls {
            command.arg("-s");
        }
        Moto::spawn(command)
    }

    /// The same server for Google Cloud Storage's client (`tests/oracles/moto_for_gcs.py`).
    fn start_for_google() -> Moto {
        let mut command = Command::new(repo().join(".venv/bin/python3"));
        command.arg(repo().join("tests/oracles/moto_for_gcs.py"));
        Moto::spawn(command)
    }

    fn spawn(mut command: Command) -> Moto {
        let mut child = command
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("moto_server starts");
        let log = child.stderr.take().expect("piped stderr");
        let mut moto = Moto {
            child,
            endpoint: String::new(),
        };
        // The server prints "Running on http://127.0.0.1:PORT" once it listens, then a line
        // per request: read on a thread to the end, so that the pipe never fills.
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(log).lines() {
                let Ok(line) = line else { break };
                if let Some((_, address)) = line.split_once("Running on ") {
                    let address = address.split_whitespace().next().unwrap_or("");
                    let _ = tx.send(address.to_owned());
                }
            }
        });
        moto.endpoint = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("moto_server listening within 60 s");
        moto
    }

    /// Runs the boto3 client on `bucket`; returns its stdout.
    fn boto3(&self, bucket: &str, args: &[&str]) -> String {
        let python = repo().join(".venv/bin/python3");
        let out = Command::new(&python)
            .arg(repo().join("tests/oracles/s3_objects.py"))
            .args([&self.endpoint, bucket])
            .args(args)
            .output()
            .unwrap_or_else(|e| panic!("{} runs: {e}", python.display()));
        assert!(out.status.success(), "boto3 {args:?}: {}", stderr(&out));
        stdout(&out)
    }

    /// Each of `keys` as boto3 sees it, by key: content type, encoding and body (hex).
    fn show(&self, bucket: &str, keys: &[&str]) -> BTreeMap<String, Value> {
        let args: Vec<&str> = ["show"].iter().chain(keys).copied().collect();
        self.boto3(bucket, &args)
            .lines()
            .map(|line| {
                let v: Value = serde_json::from_str(line).expect("a JSON line");
                (v["key"].as_str().unwrap().to_owned(), v)
            })
            .collect()
    }

    /// The variables the store reads, for this server.
    fn store_env(&self) -> Vec<(&'static str, String)> {
        vec![
            ("AWS_ENDPOINT_URL", self.endpoint.clone()),
            ("AWS_ALLOW_HTTP", "true".into()),
            ("AWS_ACCESS_KEY_ID", "test".into()),
            ("AWS_SECRET_ACCESS_KEY", "test".into()),
            ("AWS_REGION", "us-east-1".into()),
        ]
    }

    /// The variables GDAL's `/vsis3/` reads, for this server.
    fn gdal_env(&self) -> Vec<(&'static str, String)> {
        let host = self.endpoint.trim_start_matches("http://");
        vec![
            ("AWS_S3_ENDPOINT", host.to_owned()),
            ("AWS_HTTPS", "NO".into()),
            ("AWS_VIRTUAL_HOSTING", "FALSE".into()),
            ("AWS_ACCESS_KEY_ID", "test".into()),
            ("AWS_SECRET_ACCESS_KEY", "test".into()),
            ("AWS_REGION", "us-east-1".into()),
        ]
    }
}

impl Drop for Moto {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn gzipped(bytes: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(bytes).unwrap();
    gz.finish().unwrap()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn tiles_and_files_round_trip_and_carry_their_http_headers() {
    let moto = Moto::start(false);
    moto.boto3("pyramids", &["mkbucket"]);
    // A neighbour whose name extends the prefix must stay outside it.
    let other = std::env::temp_dir().join(format!("tinsmith-s3-{}.json", std::process::id()));
    std::fs::write(&other, b"{\"other\":true}").unwrap();
    moto.boto3(
        "pyramids",
        &["upload", "world/v10/layer.json", other.to_str().unwrap()],
    );
    std::fs::remove_file(&other).unwrap();

    let store = BucketStore::open_with_env("s3://pyramids/world/v1/", moto.store_env()).unwrap();
    assert_eq!(store.location(), "s3://pyramids/world/v1");
    store.probe().unwrap();

    let tile = gzipped(b"quantized-mesh, as it were: 88 bytes of header and then some");
    let plain = b"an uncompressed tile".to_vec();
    let layer = br#"{"tilejson":"2.1.0","format":"quantized-mesh-1.0"}"#.to_vec();
    assert_eq!(store.get_tile(0, 0, 0).unwrap(), None);
    assert_eq!(store.get_file("layer.json").unwrap(), None);
    store.put_tile(0, 0, 0, &tile, TileEncoding::Gzip).unwrap();
    store
        .put_tile(1, 1, 0, &plain, TileEncoding::Identity)
        .unwrap();
    store.put_file("layer.json", &layer).unwrap();
    store.put_file("shards/2-of-7.json", b"{}").unwrap();
    store.put_file("shards/1-of-7.json", b"{}").unwrap();
    store.put_file("shards/notes.txt", b"n").unwrap();

    // Read back through the store: the bytes put, never decompressed.
    assert_eq!(store.get_tile(0, 0, 0).unwrap(), Some(tile.clone()));
    assert_eq!(store.get_tile(1, 1, 0).unwrap(), Some(plain.clone()));
    assert_eq!(store.get_tile(1, 0, 0).unwrap(), None);
    assert_eq!(store.get_file("layer.json").unwrap(), Some(layer.clone()));
    assert_eq!(
        store.list_files("shards/").unwrap(),
        [
            "shards/1-of-7.json",
            "shards/2-of-7.json",
            "shards/notes.txt"
        ]
    );
    assert_eq!(
        store.list_files("shards/1").unwrap(),
        ["shards/1-of-7.json"]
    );
    assert_eq!(store.list_files("nothing/").unwrap(), Vec::<String>::new());
    assert_eq!(
        store.list_files("").unwrap(),
        [
            "0/0/0.terrain",
            "1/1/0.terrain",
            "layer.json",
            "shards/1-of-7.json",
            "shards/2-of-7.json",
            "shards/notes.txt"
        ]
    );
    assert!(matches!(
        store.put_file("../escape.json", b"{}"),
        Err(StoreError::BadName { .. })
    ));

    // Read back by boto3: the same bytes, labelled for CesiumJS.
    let seen = moto.show(
        "pyramids",
        &[
            "world/v1/0/0/0.terrain",
            "world/v1/1/1/0.terrain",
            "world/v1/layer.json",
            "world/v1/shards/notes.txt",
        ],
    );
    let gz = &seen["world/v1/0/0/0.terrain"];
    assert_eq!(gz["content_type"], "application/vnd.quantized-mesh");
    assert_eq!(gz["content_encoding"], "gzip");
    assert_eq!(gz["body"], hex(&tile));
    let identity = &seen["world/v1/1/1/0.terrain"];
    assert_eq!(identity["content_type"], "application/vnd.quantized-mesh");
    assert_eq!(identity["content_encoding"], Value::Null);
    assert_eq!(identity["body"], hex(&plain));
    let json = &seen["world/v1/layer.json"];
    assert_eq!(json["content_type"], "application/json");
    assert_eq!(json["body"], hex(&layer));
    assert_ne!(
        seen["world/v1/shards/notes.txt"]["content_type"],
        "application/json"
    );

    // Replaced, then deleted (twice: no error when absent).
    let newer = gzipped(b"a better tile");
    store.put_tile(0, 0, 0, &newer, TileEncoding::Gzip).unwrap();
    assert_eq!(store.get_tile(0, 0, 0).unwrap(), Some(newer));
    store.delete_tile(0, 0, 0).unwrap();
    store.delete_tile(0, 0, 0).unwrap();
    assert_eq!(store.get_tile(0, 0, 0).unwrap(), None);
    assert_eq!(
        moto.show("pyramids", &["world/v1/0/0/0.terrain"])["world/v1/0/0/0.terrain"]["body"],
        Value::Null
    );
    let keys = moto.boto3("pyramids", &["keys"]);
    assert_eq!(
        keys.lines().collect::<Vec<_>>(),
        [
            "world/v1/1/1/0.terrain",
            "world/v1/layer.json",
            "world/v1/shards/1-of-7.json",
            "world/v1/shards/2-of-7.json",
            "world/v1/shards/notes.txt",
            "world/v10/layer.json"
        ]
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn many_threads_write_at_once() {
    let moto = Moto::start(false);
    moto.boto3("pyramids", &["mkbucket"]);
    let store = BucketStore::open_with_env("s3://pyramids/parallel", moto.store_env()).unwrap();
    // As the pyramid builder calls it: from several threads, none inside a runtime.
    std::thread::scope(|scope| {
        for t in 0..6u32 {
            let store = &store;
            scope.spawn(move || {
                for y in 0..10u32 {
                    let bytes = format!("tile {t} {y}").into_bytes();
                    store
                        .put_tile(5, t, y, &bytes, TileEncoding::Identity)
                        .unwrap();
                }
            });
        }
    });
    let names = store.list_files("5/").unwrap();
    assert_eq!(names.len(), 60, "{names:?}");
    assert_eq!(
        store.get_tile(5, 4, 7).unwrap().as_deref(),
        Some(&b"tile 4 7"[..])
    );
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_vanished_server_fails_calls_in_bounded_time_naming_the_object() {
    let mut moto = Moto::start(false);
    moto.boto3("pyramids", &["mkbucket"]);
    let store = BucketStore::open_with_env("s3://pyramids/fault", moto.store_env()).unwrap();
    store
        .put_tile(2, 3, 1, b"before", TileEncoding::Identity)
        .unwrap();
    let _ = moto.child.kill();
    let _ = moto.child.wait();

    let started = Instant::now();
    let e = store
        .put_tile(2, 3, 1, b"after", TileEncoding::Identity)
        .unwrap_err();
    let took = started.elapsed();
    // Refused connections: 4 retries, 0.1 s doubling (about 1 s in all).
    assert!(took < Duration::from_secs(8), "took {took:?}: {e}");
    let message = e.to_string();
    assert!(
        message.contains("s3://pyramids/fault/2/3/1.terrain"),
        "{message}"
    );
    // A read that cannot reach the server is an error, not an absent tile.
    let e = store.get_tile(2, 3, 1).unwrap_err().to_string();
    assert!(e.contains("s3://pyramids/fault/2/3/1.terrain"), "{e}");
    assert!(store
        .probe()
        .unwrap_err()
        .to_string()
        .contains("s3://pyramids/fault"));
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn https_endpoints_work() {
    // moto's self-signed certificate: the client is told to accept it.
    let moto = Moto::start(true);
    assert!(moto.endpoint.starts_with("https://"), "{}", moto.endpoint);
    moto.boto3("secure", &["mkbucket"]);
    let mut env = moto.store_env();
    env.retain(|(k, _)| *k != "AWS_ALLOW_HTTP");
    env.push(("AWS_ALLOW_INVALID_CERTIFICATES", "true".into()));
    let store = BucketStore::open_with_env("s3://secure/p", env).unwrap();
    store.put_file("layer.json", b"{}").unwrap();
    assert_eq!(
        store.get_file("layer.json").unwrap().as_deref(),
        Some(&b"{}"[..])
    );
}

/// Runs `tinsmith args...` in `dir` with `env` added.
fn run_with(dir: &Dir, env: &[(&str, String)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(args)
        .envs(env.iter().map(|(k, v)| (k, v)))
        .current_dir(dir.path(""))
        .output()
        .expect("run tinsmith")
}

/// Every file under `root`, by relative path, with its bytes.
fn tree(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let relative = path.strip_prefix(root).unwrap().to_path_buf();
                files.insert(relative, std::fs::read(&path).unwrap());
            }
        }
    }
    files
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_raster_in_a_bucket_is_read_as_the_local_file() {
    let moto = Moto::start(false);
    moto.boto3("dems", &["mkbucket"]);
    let local = fixture("etopo5_2deg_i16.tif");
    moto.boto3("dems", &["upload", "etopo5_2deg_i16.tif", &local]);
    let remote = "/vsis3/dems/etopo5_2deg_i16.tif";
    let env = moto.gdal_env();
    let dir = Dir::new();

    let info = |input: &str| {
        let o = run_with(&dir, &env, &["info", input]);
        assert!(o.status.success(), "info {input}: {}", stderr(&o));
        let text = stdout(&o);
        assert!(
            text.starts_with(&format!("file:          {input}\n")),
            "{text}"
        );
        text.lines().skip(1).map(str::to_owned).collect::<Vec<_>>()
    };
    let remote_info = info(remote);
    assert_eq!(remote_info, info(&local));
    assert!(
        remote_info.contains(&"size:          180 x 90 (1 band(s), showing band 1)".into()),
        "{remote_info:?}"
    );

    for (input, out) in [(remote, "from-s3"), (local.as_str(), "from-disk")] {
        let o = run_with(
            &dir,
            &env,
            &["tiles", input, "-o", out, "--max-zoom", "2", "-q"],
        );
        assert!(o.status.success(), "tiles {input}: {}", stderr(&o));
    }
    let (from_s3, from_disk) = (tree(&dir.path("from-s3")), tree(&dir.path("from-disk")));
    assert!(from_disk.contains_key(Path::new("layer.json")));
    assert!(
        from_disk.contains_key(Path::new("2/7/3.terrain")),
        "{:?}",
        from_disk.keys()
    );
    assert_eq!(
        from_s3.keys().collect::<Vec<_>>(),
        from_disk.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in &from_disk {
        assert!(from_s3[name] == *bytes, "{} differs", name.display());
    }

    // A key that is not there fails cleanly, naming it.
    let missing = "/vsis3/dems/absent.tif";
    assert_fails_naming(&run_with(&dir, &env, &["info", missing]), &[missing]);
}

/// Every object under `prefix/` in `bucket` as boto3 reads it, by key relative to the
/// prefix: (content type, content encoding, body).
fn bucket_tree(
    moto: &Moto,
    bucket: &str,
    prefix: &str,
) -> BTreeMap<String, (Value, Value, String)> {
    let keys = moto.boto3(bucket, &["keys", &format!("{prefix}/")]);
    let keys: Vec<&str> = keys.lines().collect();
    let mut out = BTreeMap::new();
    for chunk in keys.chunks(200) {
        for (key, v) in moto.show(bucket, chunk) {
            let relative = key.strip_prefix(&format!("{prefix}/")).unwrap().to_owned();
            out.insert(
                relative,
                (
                    v["content_type"].clone(),
                    v["content_encoding"].clone(),
                    v["body"].as_str().unwrap_or("").to_owned(),
                ),
            );
        }
    }
    out
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_pyramid_goes_to_a_bucket_whole_and_in_shards_as_it_goes_to_disk() {
    let moto = Moto::start(false);
    moto.boto3("terrain", &["mkbucket"]);
    let env = moto.store_env();
    let dir = Dir::new();
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let run = |args: &[&str]| {
        let o = run_with(&dir, &env, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    for format in ["quantized-mesh", "3dtiles"] {
        let (whole, sharded) = (
            format!("s3://terrain/{format}/whole"),
            format!("s3://terrain/{format}/sharded"),
        );
        let options = ["--normals", "--format", format, "-q"];
        run(&[&["tiles", &input, "-o", format][..], &options].concat());
        run(&[&["tiles", &input, "-o", &whole][..], &options].concat());
        for i in 0..3 {
            let shard = format!("{i}/3");
            let args = ["tiles", &input, "-o", &sharded, "--shard", &shard];
            run(&[&args[..], &options].concat());
        }
        for last in ["layer.json", "tileset.json"] {
            let before_merge =
                moto.boto3("terrain", &["keys", &format!("{format}/sharded/{last}")]);
            assert!(before_merge.trim().is_empty(), "{last} before the merge");
        }
        run(&["tiles", "merge", &sharded, "-q"]);

        let local: BTreeMap<String, String> = tree(&dir.path(format))
            .into_iter()
            .filter(|(p, _)| !p.starts_with("tinsmith"))
            .map(|(p, bytes)| (p.to_string_lossy().into_owned(), hex(&bytes)))
            .collect();
        assert!(local.len() > 20);
        for prefix in ["whole", "sharded"] {
            let remote = bucket_tree(&moto, "terrain", &format!("{format}/{prefix}"));
            let pyramid: BTreeMap<&String, &String> = remote
                .iter()
                .filter(|(k, _)| !k.starts_with("tinsmith/"))
                .map(|(k, v)| (k, &v.2))
                .collect();
            assert_eq!(
                pyramid.keys().map(|k| k.as_str()).collect::<Vec<_>>(),
                local.keys().map(|k| k.as_str()).collect::<Vec<_>>(),
                "{format}/{prefix}"
            );
            for (key, body) in &local {
                assert!(
                    *pyramid[key] == *body,
                    "{format}/{prefix}/{key} differs from the local file"
                );
                let (content_type, encoding, _) = &remote[key];
                let (want_type, want_encoding) = match key.rsplit_once('.').unwrap().1 {
                    "terrain" => ("application/vnd.quantized-mesh", "gzip"),
                    "glb" => ("model/gltf-binary", ""),
                    "subtree" => ("application/octet-stream", ""),
                    _ => ("application/json", ""),
                };
                assert_eq!(content_type, want_type, "{key}");
                if !want_encoding.is_empty() {
                    assert_eq!(encoding, want_encoding, "{key}");
                } else {
                    assert!(encoding.is_null() || encoding == "", "{key}: {encoding}");
                }
            }
        }
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_bucket_that_goes_away_fails_the_run_and_a_re_run_completes_it() {
    let dir = Dir::new();
    // The Albers DEM at 4 times its resolution: a run of a few seconds.
    let big = dir.path("big.tif");
    let status = Command::new("gdal_translate")
        .args(["-q", "-outsize", "400%", "400%", "-r", "bilinear"])
        .arg(fixture("becmodel_dem_bc_albers_50m.tif"))
        .arg(&big)
        .status()
        .unwrap();
    assert!(status.success());
    let big = big.to_string_lossy().into_owned();
    let mut moto = Moto::start(false);
    moto.boto3("terrain", &["mkbucket"]);
    let env = moto.store_env();
    let child = Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(["tiles", &big, "-o", "s3://terrain/p", "--threads", "1"])
        .envs(env.iter().map(|(k, v)| (k, v)))
        .current_dir(dir.path(""))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Once the first block is written, the server goes away.
    let start = Instant::now();
    while moto
        .boto3("terrain", &["keys", "p/tinsmith/blocks/"])
        .trim()
        .is_empty()
    {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no block written"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = moto.child.kill();
    let _ = moto.child.wait();
    let out = child.wait_with_output().unwrap();
    assert_fails_naming(&out, &["s3://terrain/p"]);
    // A new server (moto keeps nothing), the same run: complete, layer.json last.
    let moto = Moto::start(false);
    moto.boto3("terrain", &["mkbucket"]);
    let o = run_with(
        &dir,
        &moto.store_env(),
        &["tiles", &big, "-o", "s3://terrain/p", "-q"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let keys = moto.boto3("terrain", &["keys", "p/"]);
    assert!(keys.lines().any(|k| k == "p/layer.json"), "{keys}");
    // A merge with shards missing publishes nothing.
    let o = run_with(
        &dir,
        &moto.store_env(),
        &[
            "tiles",
            &big,
            "-o",
            "s3://terrain/s",
            "--shard",
            "1/2",
            "-q",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run_with(
        &dir,
        &moto.store_env(),
        &["tiles", "merge", "s3://terrain/s"],
    );
    assert_fails_naming(&o, &["s3://terrain/s", "0/2", "missing"]);
    assert!(moto
        .boto3("terrain", &["keys", "s/layer.json"])
        .trim()
        .is_empty());
}

/// A service account key that sends Google Cloud Storage's XML API, unauthenticated, to
/// `endpoint` (fields `object_store` reads for test servers); returns its path.
fn google_key_for(dir: &Dir, endpoint: &str) -> String {
    let key = serde_json::json!({
        "private_key": "unused",
        "private_key_id": "unused",
        "client_email": "tinsmith@example.invalid",
        "disable_oauth": true,
        "gcs_base_url": endpoint,
    });
    let path = dir.path("google-key.json");
    std::fs::write(&path, key.to_string()).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_pyramid_goes_to_google_cloud_storage_through_its_own_client() {
    // Google Cloud Storage's XML API (which `object_store`'s client speaks) is S3's for
    // what the store does: moto serves it, and boto3 reads back what the Google client
    // wrote.
    let moto = Moto::start_for_google();
    moto.boto3("terrain", &["mkbucket"]);
    let dir = Dir::new();
    let env = vec![(
        "GOOGLE_SERVICE_ACCOUNT",
        google_key_for(&dir, &moto.endpoint),
    )];

    let store = BucketStore::open_with_env("gs://terrain/direct/", env.clone()).unwrap();
    assert_eq!(store.location(), "gs://terrain/direct");
    store.probe().unwrap();
    let tile = gzipped(b"a tile through the Google client");
    store.put_tile(3, 5, 2, &tile, TileEncoding::Gzip).unwrap();
    store.put_file("layer.json", b"{}").unwrap();
    assert_eq!(store.get_tile(3, 5, 2).unwrap(), Some(tile.clone()));
    assert_eq!(
        store.list_files("").unwrap(),
        ["3/5/2.terrain", "layer.json"]
    );
    let seen = moto.show("terrain", &["direct/3/5/2.terrain", "direct/layer.json"]);
    assert_eq!(
        seen["direct/3/5/2.terrain"]["content_type"],
        "application/vnd.quantized-mesh"
    );
    assert_eq!(seen["direct/3/5/2.terrain"]["content_encoding"], "gzip");
    assert_eq!(seen["direct/3/5/2.terrain"]["body"], hex(&tile));
    assert_eq!(
        seen["direct/layer.json"]["content_type"],
        "application/json"
    );
    store.delete_tile(3, 5, 2).unwrap();
    assert_eq!(store.get_tile(3, 5, 2).unwrap(), None);

    // The binary: the same pyramid as on disk.
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let run = |args: &[&str]| {
        let o = run_with(&dir, &env, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    run(&["tiles", &input, "-o", "local", "-q"]);
    run(&["tiles", &input, "-o", "gs://terrain/pyramid", "-q"]);
    let local: BTreeMap<String, String> = tree(&dir.path("local"))
        .into_iter()
        .filter(|(p, _)| !p.starts_with("tinsmith"))
        .map(|(p, bytes)| (p.to_string_lossy().into_owned(), hex(&bytes)))
        .collect();
    let remote: BTreeMap<String, String> = bucket_tree(&moto, "terrain", "pyramid")
        .into_iter()
        .filter(|(k, _)| !k.starts_with("tinsmith/"))
        .map(|(k, v)| (k, v.2))
        .collect();
    assert!(local.len() > 20);
    assert_eq!(remote, local);
}

#[test]
fn google_and_azure_urls_are_object_stores_and_say_what_they_lack() {
    assert!(tinsmith_store::is_object_url("gs://bucket/prefix"));
    assert!(tinsmith_store::is_object_url("AZ://container"));
    assert!(!tinsmith_store::is_object_url("gcs://bucket"));
    let no_vars: [(&str, &str); 0] = [];
    let e = BucketStore::open_with_env("gs:///prefix", no_vars)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no bucket name after gs://"), "{e}");
    // Azure needs an account: the client's own message, naming the URL.
    let e = BucketStore::open_with_env("az://container/p", no_vars)
        .unwrap_err()
        .to_string();
    assert!(e.contains("az://container/p"), "{e}");
    let emulator = [("AZURE_STORAGE_USE_EMULATOR", "true")];
    let store = BucketStore::open_with_env("az://container/p", emulator).unwrap();
    assert_eq!(store.location(), "az://container/p");
}

/// Azurite, Microsoft's Azure Storage emulator (npm, installed by `make deps` into
/// .tools), serving blobs on 127.0.0.1, killed when dropped.
struct Azurite {
    child: Child,
    /// `http://127.0.0.1:PORT`.
    endpoint: String,
    _data: Dir,
}

impl Azurite {
    /// Starts the blob service and waits until it accepts connections. Fails the test when
    /// Azurite is missing.
    fn start() -> Azurite {
        let bin = repo().join(".tools/node_modules/.bin/azurite-blob");
        assert!(
            bin.exists(),
            "oracle missing: {} (azurite); run `make deps`",
            bin.display()
        );
        // A port the system had free a moment ago.
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .expect("a free port")
            .port();
        let data = Dir::new();
        let child = Command::new(&bin)
            .args(["--blobHost", "127.0.0.1", "--blobPort", &port.to_string()])
            .args(["--silent", "--skipApiVersionCheck", "--location"])
            .arg(data.path(""))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("azurite-blob starts");
        let azurite = Azurite {
            child,
            endpoint: format!("http://127.0.0.1:{port}"),
            _data: data,
        };
        let deadline = Instant::now() + Duration::from_secs(60);
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(Instant::now() < deadline, "azurite listening within 60 s");
            std::thread::sleep(Duration::from_millis(100));
        }
        azurite
    }

    /// Runs the azure-storage-blob client on `container`; returns its stdout.
    fn client(&self, container: &str, args: &[&str]) -> String {
        let python = repo().join(".venv/bin/python3");
        let out = Command::new(&python)
            .arg(repo().join("tests/oracles/azure_blobs.py"))
            .args([&self.endpoint, container])
            .args(args)
            .output()
            .unwrap_or_else(|e| panic!("{} runs: {e}", python.display()));
        assert!(
            out.status.success(),
            "azure client {args:?}: {}",
            stderr(&out)
        );
        stdout(&out)
    }
}

impl Drop for Azurite {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
#[ignore = "needs the oracles `make deps` installs (run by `make test`)"]
fn a_pyramid_goes_to_azure_blob_storage_as_it_goes_to_disk() {
    let azurite = Azurite::start();
    azurite.client("terrain", &["mkcontainer"]);
    let dir = Dir::new();
    let env = vec![
        ("AZURE_STORAGE_USE_EMULATOR", "true".to_owned()),
        ("AZURITE_BLOB_STORAGE_URL", azurite.endpoint.clone()),
    ];
    let input = fixture("becmodel_dem_bc_albers_50m.tif");
    let run = |args: &[&str]| {
        let o = run_with(&dir, &env, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    run(&["tiles", &input, "-o", "local", "-q"]);
    run(&["tiles", &input, "-o", "az://terrain/pyramid", "-q"]);
    let local: BTreeMap<String, String> = tree(&dir.path("local"))
        .into_iter()
        .filter(|(p, _)| !p.starts_with("tinsmith"))
        .map(|(p, bytes)| (p.to_string_lossy().into_owned(), hex(&bytes)))
        .collect();
    assert!(local.len() > 20);
    let mut remote = BTreeMap::new();
    for line in azurite.client("terrain", &["dump", "pyramid/"]).lines() {
        let v: Value = serde_json::from_str(line).expect("a JSON line");
        let key = v["key"].as_str().unwrap().strip_prefix("pyramid/").unwrap();
        if key.starts_with("tinsmith/") {
            continue;
        }
        if key.ends_with(".terrain") {
            assert_eq!(v["content_type"], "application/vnd.quantized-mesh", "{key}");
            assert_eq!(v["content_encoding"], "gzip", "{key}");
        } else {
            assert_eq!(v["content_type"], "application/json", "{key}");
        }
        remote.insert(key.to_owned(), v["body"].as_str().unwrap().to_owned());
    }
    assert_eq!(remote, local);
}
