//! What `tinsmith serve` serves: a directory's files, or an MBTiles file's tiles and named
//! files. Both answer the same request paths (`{z}/{x}/{y}.terrain`, `layer.json`) with
//! the same content types and encodings, so a client cannot tell them apart.

use std::fs::File;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

use tinsmith_store::{detect_encoding, MbtilesStore, TileEncoding, TileStore};

use super::Body;
use crate::error::bail;
use crate::Result;

/// Gzip files up to this size are checked whole before being sent as gzip (tiles are a
/// few kB); larger ones by their header.
const GZIP_CHECK_BYTES: u64 = 16 << 20;

/// Where the served files come from.
#[derive(Debug)]
pub(super) enum Source {
    /// Any regular file under the directory (symbolic links followed), `index.html` for a
    /// directory.
    Directory(PathBuf),
    /// The tiles of an MBTiles file at `{z}/{x}/{y}.terrain`, its named files (`layer.json`)
    /// at their names.
    Mbtiles(Box<MbtilesStore>),
}

/// A file found for a request: what to send, as what, and whether it is gzip.
pub(super) struct Found {
    pub(super) body: Body,
    pub(super) content_type: &'static str,
    pub(super) gzip: bool,
}

impl Source {
    /// The directory at `path`, or the MBTiles file there.
    ///
    /// # Errors
    /// When `path` does not exist, or is a file that is not a quantized-mesh MBTiles file
    /// (the message names it and says why).
    pub(super) fn open(path: &Path) -> Result<Source> {
        if path.is_dir() {
            return Ok(Source::Directory(path.to_path_buf()));
        }
        if !path.exists() {
            bail!("{}: no such directory or MBTiles file", path.display());
        }
        match MbtilesStore::open(path) {
            Ok(store) => Ok(Source::Mbtiles(Box::new(store))),
            Err(e) => bail!("{e} (serve takes a directory or an MBTiles file)"),
        }
    }

    /// Whether CesiumJS would find a terrain layer here: a `layer.json` (or a 3D Tiles
    /// `tileset.json`) at the top or, for a directory, in a directory right below it.
    pub(super) fn has_layer(&self) -> bool {
        match self {
            Source::Directory(dir) => {
                // quantized-mesh's layer.json, or a 3D Tiles pyramid's tileset.json.
                let has_layer = |dir: &Path| {
                    dir.join("layer.json").is_file() || dir.join("tileset.json").is_file()
                };
                has_layer(dir)
                    || std::fs::read_dir(dir).is_ok_and(|entries| {
                        entries
                            .flatten()
                            .any(|e| e.path().is_dir() && has_layer(&e.path()))
                    })
            }
            Source::Mbtiles(store) => store.get_file("layer.json").is_ok_and(|f| f.is_some()),
        }
    }

    /// The file at `relative` (a request path made of plain names only; empty for the
    /// top), or `None` when there is none to send.
    pub(super) fn find(&self, relative: &Path) -> Option<Found> {
        match self {
            Source::Directory(root) => find_in_directory(&root.join(relative)),
            Source::Mbtiles(store) => find_in_mbtiles(store, relative),
        }
    }
}

fn find_in_directory(path: &Path) -> Option<Found> {
    let path = if path.is_dir() {
        path.join("index.html")
    } else {
        path.to_path_buf()
    };
    // Regular files only (following links): a FIFO would block the thread for good.
    let metadata = std::fs::metadata(&path).ok().filter(|m| m.is_file())?;
    let length = metadata.len();
    let mut file = File::open(&path).ok()?;
    let gzip = !has_extension(&path, "gz") && is_gzip(&mut file, length);
    file.rewind().ok()?;
    Some(Found {
        body: Body::File(file, length),
        content_type: content_type(&path),
        gzip,
    })
}

fn find_in_mbtiles(store: &MbtilesStore, relative: &Path) -> Option<Found> {
    let parts: Vec<&str> = relative
        .components()
        .map(|c| c.as_os_str().to_str())
        .collect::<Option<_>>()?;
    let name = match parts.join("/") {
        name if name.is_empty() => "index.html".to_owned(),
        name => name,
    };
    let (bytes, gzip) = match tile_address(&parts) {
        Some((z, x, y)) => {
            let (bytes, encoding) = store.get_tile_encoded(z, x, y).ok()??;
            (bytes, encoding == TileEncoding::Gzip)
        }
        None => {
            let bytes = store.get_file(&name).ok()??;
            let gzip = !name.ends_with(".gz") && detect_encoding(&bytes) == TileEncoding::Gzip;
            (bytes, gzip)
        }
    };
    Some(Found {
        body: Body::Bytes(bytes),
        content_type: content_type(Path::new(&name)),
        gzip,
    })
}

/// The tile a request path `[z, x, "y.terrain"]` names, when its numbers are written as
/// a directory pyramid's file names are (decimal, no leading zeros).
fn tile_address(parts: &[&str]) -> Option<(u8, u32, u32)> {
    let [z, x, file] = parts else {
        return None;
    };
    let y = file.strip_suffix(".terrain")?;
    fn number<T: std::str::FromStr + ToString>(s: &str) -> Option<T> {
        s.parse::<T>().ok().filter(|n| n.to_string() == s)
    }
    Some((number(z)?, number(x)?, number(y)?))
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
        "terrain" => tinsmith_store::QUANTIZED_MESH_CONTENT_TYPE,
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
    fn tile_paths_are_those_a_directory_pyramid_has() {
        assert_eq!(
            tile_address(&["12", "1308", "2906.terrain"]),
            Some((12, 1308, 2906))
        );
        assert_eq!(tile_address(&["0", "0", "0.terrain"]), Some((0, 0, 0)));
        assert_eq!(tile_address(&["012", "1308", "2906.terrain"]), None);
        assert_eq!(tile_address(&["256", "0", "0.terrain"]), None);
        assert_eq!(tile_address(&["1", "0", "0.json"]), None);
        assert_eq!(tile_address(&["1", "+0", "0.terrain"]), None);
        assert_eq!(tile_address(&["a", "1", "0", "0.terrain"]), None);
    }
}
