//! Where a terrain pyramid goes: tiles addressed by `z/x/y` and a few small named files
//! (`layer.json`, shard records) beside them, behind one trait ([`TileStore`]) so that the
//! pyramid builder does not know whether it writes a local directory, a single-file
//! container ([`MbtilesStore`]) or an object store.
//!
//! # Guarantees every store keeps
//! - A `put` either stores the whole value under its key or leaves the previous value (or
//!   none): a reader never sees half a tile.
//! - `get` after a successful `put` in the same process returns the bytes put.
//! - Keys are plain: tile `z/x/y` is `{z}/{x}/{y}.terrain`; named files are relative
//!   `/`-separated names without `..`.

mod directory;
mod encoding;
mod error;
mod mbtiles;
mod object;

pub use directory::DirectoryStore;
pub use encoding::detect_encoding;
pub use error::{StoreError, StoreResult};
pub use mbtiles::{MbtilesStore, ACCEPTED_FORMATS, MBTILES_FORMAT};
pub use object::{is_object_url, BucketStore};

/// How a tile's bytes are encoded, so a store can label them for HTTP clients.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileEncoding {
    /// Gzip-compressed quantized-mesh (served with `Content-Encoding: gzip`).
    Gzip,
    /// Plain quantized-mesh.
    Identity,
}

/// The MIME type CesiumJS asks quantized-mesh tiles for.
pub const QUANTIZED_MESH_CONTENT_TYPE: &str = "application/vnd.quantized-mesh";

/// A pyramid's destination. Implementations are shared by the builder's threads.
pub trait TileStore: Send + Sync {
    /// The destination as the user gave it (a path, `s3://bucket/prefix`), for messages.
    fn location(&self) -> String;

    /// Stores `bytes` as tile `z/x/y`, replacing any tile there.
    fn put_tile(
        &self,
        z: u8,
        x: u32,
        y: u32,
        bytes: &[u8],
        encoding: TileEncoding,
    ) -> StoreResult<()>;

    /// The bytes stored as tile `z/x/y`, or `None` when there is none.
    fn get_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<Option<Vec<u8>>>;

    /// The bytes stored as tile `z/x/y` and how they are encoded (for a server's
    /// `Content-Encoding`), or `None` when there is none. The encoding is the one the
    /// store recorded when it keeps a record, else [`detect_encoding`]'s reading of the
    /// bytes.
    fn get_tile_encoded(
        &self,
        z: u8,
        x: u32,
        y: u32,
    ) -> StoreResult<Option<(Vec<u8>, TileEncoding)>> {
        Ok(self.get_tile(z, x, y)?.map(|bytes| {
            let encoding = detect_encoding(&bytes);
            (bytes, encoding)
        }))
    }

    /// Removes tile `z/x/y`; no error when there is none.
    fn delete_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<()>;

    /// Stores the small file `name` (e.g. `layer.json`), replacing any.
    fn put_file(&self, name: &str, bytes: &[u8]) -> StoreResult<()>;

    /// The bytes of file `name`, or `None` when there is none.
    fn get_file(&self, name: &str) -> StoreResult<Option<Vec<u8>>>;

    /// Removes file `name`; no error when there is none.
    fn delete_file(&self, name: &str) -> StoreResult<()>;

    /// The names of the files whose name starts with `prefix`, sorted.
    fn list_files(&self, prefix: &str) -> StoreResult<Vec<String>>;
}

/// The key of tile `z/x/y` relative to a store's root: `{z}/{x}/{y}.terrain`.
pub fn tile_key(z: u8, x: u32, y: u32) -> String {
    format!("{z}/{x}/{y}.terrain")
}

/// Checks that `name` is a relative `/`-separated file name without empty, `.` or `..`
/// parts, as every store requires of its named files.
pub fn check_file_name(name: &str) -> StoreResult<()> {
    let fine = !name.is_empty()
        && !name.starts_with('/')
        && name
            .split('/')
            .all(|part| !part.is_empty() && part != "." && part != ".." && !part.contains('\\'));
    if fine {
        Ok(())
    } else {
        Err(StoreError::BadName {
            name: name.to_owned(),
        })
    }
}
