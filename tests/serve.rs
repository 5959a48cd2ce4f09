//! `tinsmith serve`: real HTTP over loopback, a bounded number of requests.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use tinsmith_store::TileEncoding;

use crate::util::{
    assert_fails_naming, fixture, pack_mbtiles, port_of, pyramid_tiles, serve, stderr, Dir,
};

/// Sends one request and returns (status line, lower-cased headers, body).
fn get(port: u16, method: &str, target: &str) -> (String, Vec<(String, String)>, Vec<u8>) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(s, "{method} {target} HTTP/1.1\r\nHost: localhost\r\nAccept: application/vnd.quantized-mesh,application/octet-stream;q=0.9\r\n\r\n").unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8(raw[..split].to_vec()).unwrap();
    let mut lines = head.split("\r\n");
    let status = lines.next().unwrap().to_string();
    let headers = lines
        .map(|l| {
            let (k, v) = l.split_once(": ").unwrap();
            (k.to_ascii_lowercase(), v.to_string())
        })
        .collect();
    (status, headers, raw[split + 4..].to_vec())
}

fn header<'a>(headers: &'a [(String, String)], name: &str) -> Option<&'a str> {
    headers
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

#[test]
fn serves_tiles_with_content_type_encoding_and_cors() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    let o = dir.run(&["tiles", &input, "-o", "pyramid", "--max-zoom", "12"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let tile = "/12/1308/2906.terrain";
    assert!(dir.path(&format!("pyramid{tile}")).exists());

    let (mut child, base) = serve(&dir, &["pyramid", "--max-requests", "5"]);
    let port = port_of(&base);

    let (status, headers, body) = get(port, "GET", "/layer.json");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert_eq!(header(&headers, "content-type"), Some("application/json"));
    assert_eq!(header(&headers, "access-control-allow-origin"), Some("*"));
    assert!(serde_json::from_slice::<serde_json::Value>(&body).is_ok());

    let (status, headers, body) = get(port, "GET", &format!("{tile}?v=1.0.0"));
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert_eq!(
        header(&headers, "content-type"),
        Some("application/vnd.quantized-mesh")
    );
    assert_eq!(header(&headers, "content-encoding"), Some("gzip"));
    assert_eq!(
        body,
        std::fs::read(dir.path(&format!("pyramid{tile}"))).unwrap()
    );

    let (status, headers, _) = get(port, "OPTIONS", tile);
    assert!(status.starts_with("HTTP/1.1 204"), "{status}");
    assert!(header(&headers, "access-control-allow-methods").is_some());
    assert!(get(port, "GET", "/nope.terrain").0.contains("404"));
    assert!(get(port, "GET", "/../Cargo.toml").0.contains("400"));

    // Five requests served: the server stops by itself.
    let start = Instant::now();
    loop {
        if let Some(status) = child.0.try_wait().unwrap() {
            assert!(status.success());
            break;
        }
        if start.elapsed() > Duration::from_secs(20) {
            child.0.kill().unwrap();
            panic!("server did not stop after its requests");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends `raw` bytes as the request; returns the whole response.
fn raw_request(port: u16, raw: &[u8]) -> Vec<u8> {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    s.write_all(raw).unwrap();
    let mut out = Vec::new();
    s.read_to_end(&mut out).unwrap();
    out
}

#[test]
fn only_real_gzip_is_sent_as_gzip_and_odd_requests_get_answers() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    let o = dir.run(&[
        "tiles",
        &input,
        "-o",
        "raw",
        "--max-zoom",
        "12",
        "--no-gzip",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // An uncompressed tile starts with its centre's x as a little-endian f64, whose low
    // bytes can be gzip's magic 1f 8b (about one tile in 65,536). Such a tile (here made
    // by moving the centre by a hair) must not be sent with Content-Encoding: gzip.
    let tile = "/12/1308/2906.terrain";
    let path = dir.path(&format!("raw{tile}"));
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[..3].copy_from_slice(&[0x1f, 0x8b, 0x08]);
    bytes[3] = 0;
    std::fs::write(&path, &bytes).unwrap();

    let (mut child, base) = serve(&dir, &["raw", "--max-requests", "6"]);
    let port = port_of(&base);
    let (status, headers, body) = get(port, "GET", tile);
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert_eq!(header(&headers, "content-encoding"), None);
    assert_eq!(body, bytes);
    // HEAD: the length, no body.
    let (status, headers, body) = get(port, "HEAD", tile);
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert_eq!(
        header(&headers, "content-length"),
        Some(bytes.len().to_string().as_str())
    );
    assert!(body.is_empty());
    // 405 sends the body it announces, and which methods are allowed.
    let (status, headers, body) = get(port, "POST", tile);
    assert!(status.contains("405"), "{status}");
    assert_eq!(header(&headers, "allow"), Some("GET, HEAD, OPTIONS"));
    assert_eq!(
        header(&headers, "content-length"),
        Some(body.len().to_string().as_str())
    );
    // A header value that is not UTF-8, and a target in absolute form, are served.
    let answer = raw_request(
        port,
        b"GET /layer.json HTTP/1.1\r\nHost: localhost\r\nX-Name: caf\xe9\r\n\r\n",
    );
    assert!(
        answer.starts_with(b"HTTP/1.1 200 OK"),
        "{:?}",
        String::from_utf8_lossy(&answer)
    );
    let answer = raw_request(
        port,
        format!("GET http://127.0.0.1:{port}/layer.json HTTP/1.1\r\n\r\n").as_bytes(),
    );
    assert!(
        answer.starts_with(b"HTTP/1.1 200 OK"),
        "{:?}",
        String::from_utf8_lossy(&answer)
    );
    // A 204 carries no Content-Length.
    let (status, headers, _) = get(port, "OPTIONS", tile);
    assert!(status.contains("204"), "{status}");
    assert_eq!(header(&headers, "content-length"), None);
    assert!(child.0.wait().unwrap().success());
}

#[test]
fn an_mbtiles_file_is_served_as_its_directory_is() {
    let dir = Dir::new();
    let input = fixture("tintn_valid_raster_3857.tif");
    for (name, encoding) in [("gz", TileEncoding::Gzip), ("raw", TileEncoding::Identity)] {
        let mut args = vec!["tiles", &input, "-o", name, "--max-zoom", "12"];
        if encoding == TileEncoding::Identity {
            args.push("--no-gzip");
        }
        let o = dir.run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let tiles = pyramid_tiles(&dir.path(name));
        assert!(tiles.len() > 10, "{} tiles", tiles.len());
        if encoding == TileEncoding::Identity {
            // A plain tile that begins with gzip's magic bytes (see above) stays plain.
            let mut bytes = std::fs::read(&tiles[0].3).unwrap();
            bytes[..4].copy_from_slice(&[0x1f, 0x8b, 0x08, 0x00]);
            std::fs::write(&tiles[0].3, &bytes).unwrap();
        }
        let file = format!("{name}.mbtiles");
        assert_eq!(
            pack_mbtiles(&dir.path(name), &dir.path(&file), encoding),
            tiles.len()
        );

        let (_dir_server, dir_base) = serve(&dir, &[name]);
        let (_file_server, file_base) = serve(&dir, &[&file]);
        let (dir_port, file_port) = (port_of(&dir_base), port_of(&file_base));
        let mut requests: Vec<(&str, String)> = Vec::new();
        for (z, x, y, _) in &tiles {
            requests.push(("GET", format!("/{z}/{x}/{y}.terrain?v=1.0.0")));
        }
        let (z, x, y, _) = &tiles[tiles.len() / 2];
        for target in [
            "/layer.json",
            "/./layer.json?v=2",
            "/",
            "/9/0/0.terrain",
            "/12/01308/2906.terrain",
            "/nope.json",
            "/../Cargo.toml",
        ] {
            requests.push(("GET", target.to_string()));
        }
        for method in ["HEAD", "OPTIONS", "POST"] {
            requests.push((method, format!("/{z}/{x}/{y}.terrain")));
        }
        for (method, target) in &requests {
            let from_dir = get(dir_port, method, target);
            let from_file = get(file_port, method, target);
            assert_eq!(from_dir, from_file, "{method} {target} ({name})");
        }
        // What both sent is what the directory holds, labelled as it is encoded.
        for (z, x, y, path) in &tiles {
            let (status, headers, body) = get(file_port, "GET", &format!("/{z}/{x}/{y}.terrain"));
            assert_eq!(status, "HTTP/1.1 200 OK");
            assert_eq!(body, std::fs::read(path).unwrap());
            let gzip = (encoding == TileEncoding::Gzip).then_some("gzip");
            assert_eq!(header(&headers, "content-encoding"), gzip, "{path:?}");
            assert_eq!(
                header(&headers, "content-type"),
                Some("application/vnd.quantized-mesh")
            );
            assert_eq!(header(&headers, "access-control-allow-origin"), Some("*"));
        }
        let (status, headers, body) = get(file_port, "GET", "/layer.json");
        assert_eq!(status, "HTTP/1.1 200 OK");
        assert_eq!(header(&headers, "content-type"), Some("application/json"));
        assert_eq!(
            body,
            std::fs::read(dir.path(name).join("layer.json")).unwrap()
        );
    }
}

#[test]
fn a_file_that_is_not_mbtiles_is_refused_by_name() {
    let dir = Dir::new();
    dir.write(
        "notes.mbtiles",
        "some text that is not an SQLite database at all\n",
    );
    let o = dir.run(&["serve", "notes.mbtiles", "--port", "0"]);
    assert_fails_naming(&o, &["notes.mbtiles", "not an SQLite database"]);
    let o = dir.run(&["serve", "missing.mbtiles", "--port", "0"]);
    assert_fails_naming(
        &o,
        &["missing.mbtiles", "no such directory or MBTiles file"],
    );
}
