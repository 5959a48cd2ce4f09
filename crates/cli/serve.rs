//! `tinsmith serve`: a small static file server on 127.0.0.1 for trying a terrain pyramid
//! in CesiumJS: quantized-mesh and JSON content types, `Content-Encoding: gzip` for
//! gzipped tiles, CORS for pages on other origins.
//!
//! std::net, one thread per connection, `Connection: close`: enough for a local viewer,
//! no dependency to keep up to date. Not meant to face a network (see docs/serving.md for
//! nginx and Apache).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Ipv4Addr, TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};

use anyhow::{Context, Result};

use crate::args::ServeArgs;

/// The longest request head read.
const MAX_HEAD: usize = 16 * 1024;

pub fn run(args: &ServeArgs) -> Result<bool> {
    anyhow::ensure!(args.dir.is_dir(), "{}: not a directory", args.dir.display());
    let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, args.port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{}", args.port))?;
    let addr = listener.local_addr()?;
    println!("serving {} at http://{addr}/", args.dir.display());
    std::io::stdout().flush()?;
    let mut handlers = Vec::new();
    for (served, stream) in listener.incoming().enumerate() {
        let Ok(stream) = stream else { continue };
        let root = args.dir.clone();
        handlers.push(std::thread::spawn(move || {
            // A failed connection only concerns its client.
            let _ = handle(stream, &root);
        }));
        handlers.retain(|h| !h.is_finished());
        if args
            .max_requests
            .is_some_and(|max| served as u64 + 1 >= max)
        {
            break;
        }
    }
    for h in handlers {
        let _ = h.join();
    }
    Ok(true)
}

/// A response's status line and headers, before the body.
struct Head {
    status: &'static str,
    headers: Vec<(&'static str, String)>,
}

fn handle(stream: TcpStream, root: &Path) -> std::io::Result<()> {
    stream.set_read_timeout(Some(std::time::Duration::from_secs(10)))?;
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request_line = String::new();
    reader
        .by_ref()
        .take(MAX_HEAD as u64)
        .read_line(&mut request_line)?;
    // Skip the rest of the head.
    let mut read = request_line.len();
    loop {
        let mut line = String::new();
        let n = reader.by_ref().take(MAX_HEAD as u64).read_line(&mut line)?;
        read += n;
        if n == 0 || line == "\r\n" || line == "\n" || read > MAX_HEAD {
            break;
        }
    }
    let mut parts = request_line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let (head, body) = respond(method, target, root);
    let mut out = std::io::BufWriter::new(stream);
    write!(out, "HTTP/1.1 {}\r\n", head.status)?;
    for (name, value) in &head.headers {
        write!(out, "{name}: {value}\r\n")?;
    }
    let length = body.as_ref().map_or(0, |b| b.len());
    write!(
        out,
        "Content-Length: {length}\r\nConnection: close\r\n\
         Access-Control-Allow-Origin: *\r\n\
         Access-Control-Allow-Methods: GET, HEAD, OPTIONS\r\n\
         Access-Control-Allow-Headers: *\r\n\r\n"
    )?;
    if method == "GET" {
        if let Some(body) = body {
            out.write_all(&body)?;
        }
    }
    out.flush()
}

fn respond(method: &str, target: &str, root: &Path) -> (Head, Option<Vec<u8>>) {
    let plain = |status, text: &str| {
        (
            Head {
                status,
                headers: vec![("Content-Type", "text/plain; charset=utf-8".into())],
            },
            Some(text.as_bytes().to_vec()),
        )
    };
    match method {
        "GET" | "HEAD" => {}
        "OPTIONS" => {
            return (
                Head {
                    status: "204 No Content",
                    headers: vec![],
                },
                None,
            )
        }
        _ => return plain("405 Method Not Allowed", "method not allowed\n"),
    }
    let Some(path) = file_path(root, target) else {
        return plain("400 Bad Request", "bad path\n");
    };
    let path = if path.is_dir() {
        path.join("index.html")
    } else {
        path
    };
    let Ok(bytes) = std::fs::read(&path) else {
        return plain("404 Not Found", "not found\n");
    };
    let mut headers = vec![("Content-Type", content_type(&path).to_string())];
    if bytes.starts_with(&[0x1f, 0x8b]) && !has_extension(&path, "gz") {
        headers.push(("Content-Encoding", "gzip".into()));
    }
    if has_extension(&path, "terrain") {
        headers.push(("Vary", "Accept".into()));
    }
    (
        Head {
            status: "200 OK",
            headers,
        },
        Some(bytes),
    )
}

/// The file a request target names under `root`: query dropped, `%XX` decoded, and
/// refused when it would leave `root` (`..`, absolute parts).
fn file_path(root: &Path, target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next()?;
    let path = path.strip_prefix('/')?;
    let decoded = percent_decode(path)?;
    let relative = Path::new(&decoded);
    if !relative
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return None;
    }
    Some(root.join(relative))
}

fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

fn content_type(path: &Path) -> &'static str {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "terrain" => "application/vnd.quantized-mesh",
        "json" => "application/json",
        "html" | "htm" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript",
        "css" => "text/css",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "svg" => "image/svg+xml",
        "wasm" => "application/wasm",
        "xml" => "application/xml",
        "glb" => "model/gltf-binary",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_under_the_root() {
        let root = Path::new("/srv/t");
        assert_eq!(
            file_path(root, "/0/1/0.terrain?v=1.0.0"),
            Some(PathBuf::from("/srv/t/0/1/0.terrain"))
        );
        assert_eq!(
            file_path(root, "/a%20b.json"),
            Some(PathBuf::from("/srv/t/a b.json"))
        );
        assert_eq!(file_path(root, "/../etc/passwd"), None);
        assert_eq!(file_path(root, "/%2e%2e/etc/passwd"), None);
        assert_eq!(file_path(root, "relative"), None);
    }
}
