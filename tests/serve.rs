//! `tinsmith serve`: real HTTP over loopback, a bounded number of requests.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::{fixture, stderr, Dir};

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

    let mut child = Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(["serve", "pyramid", "--port", "0", "--max-requests", "5"])
        .current_dir(dir.tmp.path())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let port: u16 = line
        .trim()
        .rsplit(':')
        .next()
        .unwrap()
        .trim_end_matches('/')
        .parse()
        .unwrap_or_else(|_| panic!("no port in {line:?}"));

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
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success());
            break;
        }
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("server did not stop after its requests");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}
