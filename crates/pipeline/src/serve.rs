//! `tinsmith serve`: a small static file server on 127.0.0.1 for trying a terrain pyramid
//! in CesiumJS: quantized-mesh and JSON content types, `Content-Encoding: gzip` for
//! gzipped tiles, CORS for pages on other origins.
//!
//! std::net, one thread per connection, `Connection: close`: enough for a local viewer,
//! no dependency to keep up to date. Not meant to face a network (see docs/serving.md for
//! nginx and Apache).

use std::fs::File;
use std::io::{BufReader, ErrorKind, Read, Seek, Write};
use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::error::{bail, Context};
use crate::Feedback;
use crate::Result;

/// The longest request head read.
const MAX_HEAD: usize = 16 * 1024;
/// The time a client has to send its whole request head.
const HEAD_DEADLINE: Duration = Duration::from_secs(10);
/// The time one write of the response may stall (a client that stops reading).
const WRITE_TIMEOUT: Duration = Duration::from_secs(30);
/// Connections served at once; more are closed at once (a local viewer opens a few).
const MAX_CONNECTIONS: usize = 256;
/// Gzip files up to this size are checked whole before being sent as gzip (tiles are a
/// few kB); larger ones by their header.
const GZIP_CHECK_BYTES: u64 = 16 << 20;

/// A local HTTP server for a directory (a terrain pyramid), bound to 127.0.0.1 and not
/// yet serving: [`Server::addr`] says where, [`Server::run`] serves.
#[derive(Debug)]
pub struct Server {
    dir: PathBuf,
    listener: TcpListener,
}

/// What [`serve`] serves and where.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The directory served (made by `tinsmith tiles`).
    pub dir: PathBuf,
    /// Port on 127.0.0.1; 0 picks a free one.
    pub port: u16,
    /// Stop after this many requests (for tests); `None` serves until killed.
    pub max_requests: Option<u64>,
}

/// Binds a server for `options.dir` on 127.0.0.1; fails, naming it, when the directory is
/// missing or the port taken. Notes when the directory holds no `layer.json` (CesiumJS
/// would not load it as terrain).
pub fn serve(options: &ServeOptions, feedback: &dyn Feedback) -> Result<Server> {
    let dir = &options.dir;
    if !dir.exists() {
        bail!("{}: no such directory", dir.display());
    }
    if !dir.is_dir() {
        bail!("{}: not a directory", dir.display());
    }
    let has_layer = |dir: &Path| dir.join("layer.json").is_file();
    let pyramid_below = std::fs::read_dir(dir).is_ok_and(|entries| {
        entries
            .flatten()
            .any(|e| e.path().is_dir() && has_layer(&e.path()))
    });
    if !has_layer(dir) && !pyramid_below {
        feedback.note(&format!(
            "{}: note: no layer.json here, so CesiumJS will not load it as a terrain \
             pyramid (serve the directory `tinsmith tiles -o` made)",
            dir.display()
        ));
    }
    let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, options.port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{}", options.port))?;
    Ok(Server {
        dir: dir.clone(),
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
                let root = self.dir.clone();
                let count = Arc::clone(&open);
                let spawned = std::thread::Builder::new().spawn(move || {
                    let _ = handle(stream, &root);
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
}

fn handle(stream: TcpStream, root: &Path) -> std::io::Result<()> {
    let Some(request_line) = read_head(&stream)? else {
        return Ok(());
    };
    let request_line = String::from_utf8_lossy(&request_line);
    let mut parts = request_line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let (head, body) = respond(method, target, root);
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

fn respond(method: &str, target: &str, root: &Path) -> (Head, Body) {
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
    let Some(path) = file_path(root, target) else {
        return plain("400 Bad Request", "bad path\n");
    };
    let path = if path.is_dir() {
        path.join("index.html")
    } else {
        path
    };
    // Regular files only (following links): a FIFO would block the thread for good.
    let file = match std::fs::metadata(&path) {
        Ok(m) if m.is_file() => File::open(&path).ok().map(|f| (f, m.len())),
        _ => None,
    };
    let Some((mut file, length)) = file else {
        return plain("404 Not Found", "not found\n");
    };
    let mut headers = vec![("Content-Type", content_type(&path).to_string())];
    let gzip = !has_extension(&path, "gz") && is_gzip(&mut file, length);
    if file.rewind().is_err() {
        return plain("404 Not Found", "not found\n");
    }
    if gzip {
        headers.push(("Content-Encoding", "gzip".into()));
    }
    (
        Head {
            status: "200 OK",
            headers,
        },
        Body::File(file, length),
    )
}

/// Whether `file` (read from its start; the caller rewinds it after) is gzip: its header
/// names deflate with no reserved flags, and (up to [`GZIP_CHECK_BYTES`]) the whole
/// member decompresses with a matching checksum. An uncompressed tile (`tiles --no-gzip`)
/// begins with an `f64` whose low bytes are arbitrary and can match gzip's two magic
/// bytes; it must not be sent as gzip.
fn is_gzip(file: &mut File, length: u64) -> bool {
    let mut header = [0u8; 4];
    if file.read_exact(&mut header).is_err()
        || header[..3] != [0x1f, 0x8b, 0x08]
        || header[3] & 0xe0 != 0
    {
        return false;
    }
    if length > GZIP_CHECK_BYTES {
        return true;
    }
    if file.rewind().is_err() {
        return false;
    }
    let mut decoder = flate2::read::GzDecoder::new(file);
    std::io::copy(&mut decoder, &mut std::io::sink()).is_ok()
}

/// The file a request target names under `root`: query dropped, `%XX` decoded, and
/// refused when it would leave `root` (`..`, absolute parts).
fn file_path(root: &Path, target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next()?;
    // The absolute form (`http://host:port/path`), which servers must accept.
    let path = match path.split_once("://") {
        Some((scheme, rest)) if scheme.eq_ignore_ascii_case("http") => &rest[rest.find('/')?..],
        _ => path,
    };
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
        assert_eq!(
            file_path(root, "http://127.0.0.1:8000/layer.json"),
            Some(PathBuf::from("/srv/t/layer.json"))
        );
        assert_eq!(file_path(root, "http://127.0.0.1:8000"), None);
    }
}
