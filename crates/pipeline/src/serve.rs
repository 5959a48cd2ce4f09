//! `tinsmith serve`: a small static file server on 127.0.0.1 for trying a terrain pyramid
//! in CesiumJS: quantized-mesh and JSON content types, `Content-Encoding: gzip` for
//! gzipped tiles, CORS for pages on other origins. The pyramid is a directory or an
//! MBTiles file (see the `source` module), served alike.
//!
//! std::net, one thread per connection, `Connection: close`: enough for a local viewer,
//! no dependency to keep up to date. Not meant to face a network (see docs/serving.md for
//! nginx and Apache).

mod source;

use std::fs::File;
use std::io::{BufReader, ErrorKind, Read, Write};
use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::error::Context;
use crate::Feedback;
use crate::Result;
use source::Source;

/// The longest request head read.
const MAX_HEAD: usize = 16 * 1024;
/// The time a client has to send its whole request head.
const HEAD_DEADLINE: Duration = Duration::from_secs(10);
/// The time one write of the response may stall (a client that stops reading).
const WRITE_TIMEOUT: Duration = Duration::from_secs(30);
/// Connections served at once; more are closed at once (a local viewer opens a few).
const MAX_CONNECTIONS: usize = 256;

/// A local HTTP server for a terrain pyramid (a directory or an MBTiles file), bound to
/// 127.0.0.1 and not yet serving: [`Server::addr`] says where, [`Server::run`] serves.
#[derive(Debug)]
pub struct Server {
    source: Arc<Source>,
    listener: TcpListener,
}

/// What [`serve`] serves and where.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The directory or MBTiles file served (made by `tinsmith tiles`).
    pub path: PathBuf,
    /// Port on 127.0.0.1; 0 picks a free one.
    pub port: u16,
    /// Stop after this many requests (for tests); `None` serves until killed.
    pub max_requests: Option<u64>,
}

/// Binds a server for `options.path` (a directory, or an MBTiles file of quantized-mesh
/// tiles) on 127.0.0.1; fails, naming it, when it is missing, a file that is not such an
/// MBTiles file, or the port is taken. Notes when there is no `layer.json` or
/// `tileset.json` (CesiumJS would not load it as terrain).
pub fn serve(options: &ServeOptions, feedback: &dyn Feedback) -> Result<Server> {
    let path = &options.path;
    let source = Source::open(path)?;
    if !source.has_layer() {
        feedback.note(&format!(
            "{}: note: no layer.json (or tileset.json) here, so CesiumJS will not load it \
             as a terrain pyramid (serve the directory or MBTiles file `tinsmith tiles -o` made)",
            path.display()
        ));
    }
    let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, options.port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{}", options.port))?;
    Ok(Server {
        source: Arc::new(source),
        listener,
    })
}

impl Server {
    /// The address it listens on.
    pub fn addr(&self) -> Result<SocketAddr> {
        Ok(self.listener.local_addr()?)
    }

    /// Serves, a thread per connection (at most [`MAX_CONNECTIONS`] at once), until
    /// `max_requests` requests have come (forever when `None`).
    pub fn run(self, max_requests: Option<u64>) -> Result<()> {
        let open = Arc::new(AtomicUsize::new(0));
        let mut handlers = Vec::new();
        for (served, stream) in self.listener.incoming().enumerate() {
            let Ok(stream) = stream else { continue };
            handlers.retain(|h: &std::thread::JoinHandle<()>| !h.is_finished());
            // Over the cap (or when no thread can be started) the connection is closed
            // unanswered: it only concerns its client.
            if open.load(Ordering::Acquire) < MAX_CONNECTIONS {
                open.fetch_add(1, Ordering::AcqRel);
                let source = Arc::clone(&self.source);
                let count = Arc::clone(&open);
                let spawned = std::thread::Builder::new().spawn(move || {
                    let _ = handle(stream, &source);
                    count.fetch_sub(1, Ordering::AcqRel);
                });
                match spawned {
                    Ok(handler) => handlers.push(handler),
                    Err(_) => {
                        open.fetch_sub(1, Ordering::AcqRel);
                    }
                }
            }
            if max_requests.is_some_and(|max| served as u64 + 1 >= max) {
                break;
            }
        }
        for h in handlers {
            let _ = h.join();
        }
        Ok(())
    }
}

/// A response's status line and headers, before the body.
struct Head {
    status: &'static str,
    headers: Vec<(&'static str, String)>,
}

/// What follows a response's head.
enum Body {
    /// No body, and no `Content-Length` (204).
    Nothing,
    /// A short text.
    Text(&'static str),
    /// A file, streamed, of this length.
    File(File, u64),
    /// Bytes read already (a tile or file of an MBTiles file).
    Bytes(Vec<u8>),
}

fn handle(stream: TcpStream, source: &Source) -> std::io::Result<()> {
    let Some(request_line) = read_head(&stream)? else {
        return Ok(());
    };
    let request_line = String::from_utf8_lossy(&request_line);
    let mut parts = request_line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let (head, body) = respond(method, target, source);
    stream.set_write_timeout(Some(WRITE_TIMEOUT))?;
    let mut out = std::io::BufWriter::new(&stream);
    write!(out, "HTTP/1.1 {}\r\n", head.status)?;
    for (name, value) in &head.headers {
        write!(out, "{name}: {value}\r\n")?;
    }
    match &body {
        Body::Nothing => {}
        Body::Text(text) => write!(out, "Content-Length: {}\r\n", text.len())?,
        Body::File(_, length) => write!(out, "Content-Length: {length}\r\n")?,
        Body::Bytes(bytes) => write!(out, "Content-Length: {}\r\n", bytes.len())?,
    }
    write!(
        out,
        "Connection: close\r\n\
         Access-Control-Allow-Origin: *\r\n\
         Access-Control-Allow-Methods: GET, HEAD, OPTIONS\r\n\
         Access-Control-Allow-Headers: *\r\n\r\n"
    )?;
    if method != "HEAD" {
        match body {
            Body::Nothing => {}
            Body::Text(text) => out.write_all(text.as_bytes())?,
            Body::File(file, _) => {
                std::io::copy(&mut BufReader::new(file), &mut out)?;
            }
            Body::Bytes(bytes) => out.write_all(&bytes)?,
        }
    }
    out.flush()
}

/// Reads the request head within [`HEAD_DEADLINE`] and [`MAX_HEAD`] bytes (as bytes: a
/// header may hold any octet); returns its first line, or `None` when the client sent
/// none in time.
fn read_head(mut stream: &TcpStream) -> std::io::Result<Option<Vec<u8>>> {
    let deadline = Instant::now() + HEAD_DEADLINE;
    let mut head: Vec<u8> = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            break;
        }
        stream.set_read_timeout(Some(left))?;
        let n = match stream.read(&mut chunk) {
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => break,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        head.extend_from_slice(&chunk[..n]);
        let text = head.trim_ascii_start();
        let ended =
            text.windows(4).any(|w| w == b"\r\n\r\n") || text.windows(2).any(|w| w == b"\n\n");
        if n == 0 || ended || head.len() >= MAX_HEAD {
            break;
        }
    }
    let text = head.trim_ascii_start();
    let first = text.split(|&b| b == b'\n').next().unwrap_or(&[]);
    Ok((!first.is_empty()).then(|| first.to_vec()))
}

fn respond(method: &str, target: &str, source: &Source) -> (Head, Body) {
    let plain = |status, text: &'static str| {
        (
            Head {
                status,
                headers: vec![("Content-Type", "text/plain; charset=utf-8".into())],
            },
            Body::Text(text),
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
                Body::Nothing,
            )
        }
        "" => return plain("400 Bad Request", "bad request\n"),
        _ => {
            let (mut head, body) = plain("405 Method Not Allowed", "method not allowed\n");
            head.headers.push(("Allow", "GET, HEAD, OPTIONS".into()));
            return (head, body);
        }
    }
    let Some(relative) = request_path(target) else {
        return plain("400 Bad Request", "bad path\n");
    };
    let Some(found) = source.find(&relative) else {
        return plain("404 Not Found", "not found\n");
    };
    let mut headers = vec![("Content-Type", found.content_type.to_string())];
    if found.gzip {
        headers.push(("Content-Encoding", "gzip".into()));
    }
    (
        Head {
            status: "200 OK",
            headers,
        },
        found.body,
    )
}

/// The path a request target names, relative to what is served: query dropped, `%XX`
/// decoded, `.` parts dropped, and refused when it would leave the top (`..`, absolute
/// parts).
fn request_path(target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next()?;
    // The absolute form (`http://host:port/path`), which servers must accept.
    let path = match path.split_once("://") {
        Some((scheme, rest)) if scheme.eq_ignore_ascii_case("http") => &rest[rest.find('/')?..],
        _ => path,
    };
    let path = path.strip_prefix('/')?;
    let decoded = percent_decode(path)?;
    let mut relative = PathBuf::new();
    for component in Path::new(&decoded).components() {
        match component {
            Component::Normal(part) => relative.push(part),
            Component::CurDir => {}
            _ => return None,
        }
    }
    Some(relative)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_under_the_top() {
        assert_eq!(
            request_path("/0/1/0.terrain?v=1.0.0"),
            Some(PathBuf::from("0/1/0.terrain"))
        );
        assert_eq!(
            request_path("/./0/./1/0.terrain"),
            Some(PathBuf::from("0/1/0.terrain"))
        );
        assert_eq!(request_path("/a%20b.json"), Some(PathBuf::from("a b.json")));
        assert_eq!(request_path("/"), Some(PathBuf::new()));
        assert_eq!(request_path("/../etc/passwd"), None);
        assert_eq!(request_path("/%2e%2e/etc/passwd"), None);
        assert_eq!(request_path("/a/../../etc/passwd"), None);
        assert_eq!(request_path("//etc/passwd"), None);
        assert_eq!(request_path("relative"), None);
        assert_eq!(
            request_path("http://127.0.0.1:8000/layer.json"),
            Some(PathBuf::from("layer.json"))
        );
        assert_eq!(request_path("http://127.0.0.1:8000"), None);
    }
}
