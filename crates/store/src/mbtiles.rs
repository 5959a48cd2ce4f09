//! A pyramid in one MBTiles 1.3 file: an SQLite database with a `tiles` table (tile
//! `z/x/y` at `zoom_level` z, `tile_column` x, `tile_row` y: the pyramid's y is TMS already,
//! as MBTiles wants) and a `metadata` table of text rows.
//!
//! # What the file holds
//! - `tiles(zoom_level, tile_column, tile_row, tile_data)` with the unique index
//!   `tile_index`; each tile's bytes as they were put, gzipped or not.
//! - `metadata(name, value)` with the unique index `name`, and these rows:
//!   - `format`: `application/vnd.quantized-mesh` ([`MBTILES_FORMAT`]). MBTiles 1.3 asks for
//!     a media type for formats other than its own, and quantized-mesh has none registered:
//!     this is the one CesiumJS asks tiles for (and `tinsmith serve` answers with). Files
//!     from other tools that say `quantized-mesh-1.0` (the `format` of `layer.json`) are
//!     read as well ([`ACCEPTED_FORMATS`]).
//!   - `name` (the file's stem unless set), `minzoom`, `maxzoom` (of the tiles stored),
//!     `bounds` (`west,south,east,north` in degrees, from `layer.json`'s `bounds`).
//!   - `json`: the whole `layer.json`, the file CesiumJS reads first. `json` is MBTiles'
//!     row for a tileset's JSON description (TileJSON fields such as a vector tileset's
//!     layers); the terrain packers that write quantized-mesh MBTiles put the layer's
//!     `available` and `extensions` there, so that is where readers look.
//!   - `content_encoding`: `gzip` or `identity` when every tile put had that encoding, so a
//!     server can label the tiles without guessing; a file without it (or one whose tiles
//!     were mixed) is read by [`detect_encoding`](crate::detect_encoding).
//!   - any other named file put (a pyramid's records, `tinsmith/top.json`) is a row of the
//!     extra table `tinsmith_files (name, data)`, which MBTiles readers ignore; a
//!     `file:{name}` metadata row (as earlier files hold) is read as that file too.
//!
//! # All or nothing
//! [`MbtilesStore::create`] builds the file as a `.tinsmith-*.tmp` temporary beside the
//! target (`tinsmith_output::StagedFile`: locked, registered for removal on a signal,
//! swept by a later run when a killed run left it) and [`MbtilesStore::commit`] renames it
//! over the target. Dropped without `commit`, the temporary is removed and the target
//! stays as it was. The temporary is written with SQLite's journal in memory and without
//! syncs (a crash loses only the temporary); `commit` syncs it before the rename.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use rusqlite::types::ValueRef;
use rusqlite::{params, Connection, ErrorCode, OpenFlags, OptionalExtension};
use tinsmith_output::StagedFile;

use crate::{check_file_name, detect_encoding, StoreError, StoreResult, TileEncoding, TileStore};

/// The `format` metadata value written: the media type CesiumJS asks quantized-mesh tiles
/// for (no value is registered for quantized-mesh in MBTiles or with IANA).
pub const MBTILES_FORMAT: &str = crate::QUANTIZED_MESH_CONTENT_TYPE;

/// The `format` values [`MbtilesStore::open`] takes for quantized-mesh terrain: ours, and
/// `quantized-mesh-1.0`, which other terrain packers write (the `format` of `layer.json`).
pub const ACCEPTED_FORMATS: [&str; 2] = [MBTILES_FORMAT, "quantized-mesh-1.0"];

/// MBTiles' SQLite application id ("MPBX", spec 1.3), set in the files made here.
const APPLICATION_ID: i32 = 0x4d50_4258;
/// The metadata row that holds `layer.json`.
const LAYER_JSON_ROW: &str = "json";
/// The prefix of the metadata rows that hold the other named files.
const FILE_ROW_PREFIX: &str = "file:";

/// The table that holds the named files other than `layer.json` (a pyramid's records),
/// made when the first is put: MBTiles readers ignore tables they do not know.
const FILES_TABLE: &str =
    "CREATE TABLE IF NOT EXISTS tinsmith_files (name text PRIMARY KEY, data blob)";

/// Whether the database has table `name`.
fn has_table(conn: &Connection, name: &str) -> rusqlite::Result<bool> {
    conn.prepare_cached("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?1")?
        .query_row([name], |_| Ok(()))
        .optional()
        .map(|row| row.is_some())
}
/// The metadata row that says how every tile is encoded.
const ENCODING_ROW: &str = "content_encoding";
/// Writes per transaction: large enough that commits cost nothing next to the inserts,
/// small enough that SQLite's cache of the open transaction stays small.
const WRITES_PER_TRANSACTION: usize = 4096;

/// The connection and what the writes so far have recorded.
#[derive(Debug)]
struct Db {
    conn: Connection,
    /// Writes in the transaction open now (0: none is open).
    writes: usize,
    /// The encodings of the tiles put: bit 0 gzip, bit 1 identity.
    encodings_put: u8,
}

/// An MBTiles file: being built ([`MbtilesStore::create`], written through [`TileStore`],
/// published by [`MbtilesStore::commit`]) or read ([`MbtilesStore::open`], whose `put`s
/// fail). Shared by threads: one connection behind a mutex.
#[derive(Debug)]
pub struct MbtilesStore {
    // Declared first so that it is dropped (the connection closed) before the temporary
    // file is removed.
    db: Mutex<Db>,
    /// The file as given: the target while building, the file read otherwise.
    path: PathBuf,
    /// While building: the temporary file the database is in.
    staged: Option<StagedFile>,
    /// When read: the encoding the file records for every tile, if it does.
    recorded_encoding: Option<TileEncoding>,
}

impl MbtilesStore {
    /// Starts a new MBTiles file that [`MbtilesStore::commit`] will put at `path` (a
    /// symbolic link there stays a link to the new file), replacing any file there.
    ///
    /// # Errors
    /// [`StoreError::Unusable`] when `path` is a directory; [`StoreError::Io`] when the
    /// temporary file cannot be made beside it (its directory missing, no permission) or
    /// the run was interrupted.
    pub fn create(path: &Path) -> StoreResult<MbtilesStore> {
        let location = path.display().to_string();
        let target = tinsmith_output::resolve_output(path);
        if target.is_dir() {
            return Err(StoreError::Unusable {
                location,
                reason: "is a directory, not an MBTiles file".into(),
            });
        }
        let io = |source| StoreError::Io {
            location: location.clone(),
            source,
        };
        let staged = StagedFile::new(&target).map_err(io)?;
        if tinsmith_output::interrupted() {
            // The signal handler may have passed already: dropping `staged` removes it.
            return Err(io(std::io::ErrorKind::Interrupted.into()));
        }
        let sqlite = |e| sqlite_error(path, e);
        let conn = Connection::open_with_flags(
            staged.path(),
            OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(sqlite)?;
        // The temporary is private to this run until the rename: no journal file beside it
        // (it would outlive a kill under a name no sweep knows), no syncs but the last.
        let mode: String = conn
            .query_row("PRAGMA journal_mode = MEMORY", [], |r| r.get(0))
            .map_err(sqlite)?;
        debug_assert_eq!(mode.to_ascii_lowercase(), "memory");
        conn.execute_batch(&format!(
            "PRAGMA synchronous = OFF;
             PRAGMA application_id = {APPLICATION_ID};
             CREATE TABLE metadata (name text, value text);
             CREATE UNIQUE INDEX name ON metadata (name);
             CREATE TABLE tiles (zoom_level integer, tile_column integer, tile_row integer, \
                                 tile_data blob);
             CREATE UNIQUE INDEX tile_index ON tiles (zoom_level, tile_column, tile_row);"
        ))
        .map_err(sqlite)?;
        Ok(MbtilesStore {
            db: Mutex::new(Db {
                conn,
                writes: 0,
                encodings_put: 0,
            }),
            path: path.to_path_buf(),
            staged: Some(staged),
            recorded_encoding: None,
        })
    }

    /// Opens the existing MBTiles file at `path` for reading (its `put`s and `delete`s
    /// fail). Any MBTiles file whose `format` is a quantized-mesh one
    /// ([`ACCEPTED_FORMATS`]), or is missing, is taken.
    ///
    /// # Errors
    /// Each naming the file: [`StoreError::Io`] when it cannot be read;
    /// [`StoreError::Unusable`] when it is not a file, not an SQLite database, has no
    /// MBTiles `metadata` and `tiles` tables, or holds tiles of another `format`.
    pub fn open(path: &Path) -> StoreResult<MbtilesStore> {
        let location = path.display().to_string();
        let unusable = |reason: String| StoreError::Unusable {
            location: location.clone(),
            reason,
        };
        let meta = std::fs::metadata(path).map_err(|source| StoreError::Io {
            location: location.clone(),
            source,
        })?;
        if !meta.is_file() {
            return Err(unusable("is not a file, so not an MBTiles file".into()));
        }
        let conn = Connection::open_with_flags(
            path,
            OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(|e| sqlite_error(path, e))?;
        // The first statement reads the schema: that is where a file that is not SQLite
        // fails.
        for (table, columns) in [
            ("metadata", "name, value"),
            ("tiles", "zoom_level, tile_column, tile_row, tile_data"),
        ] {
            if let Err(e) = conn.prepare(&format!("SELECT {columns} FROM {table} LIMIT 0")) {
                return Err(match e.sqlite_error_code() {
                    Some(ErrorCode::NotADatabase) => {
                        unusable("is not an SQLite database, so not an MBTiles file".into())
                    }
                    Some(ErrorCode::Unknown) | None => unusable(format!(
                        "is not an MBTiles file: it has no `{table}` table with columns \
                         {columns} ({e})"
                    )),
                    Some(_) => sqlite_error(path, e),
                });
            }
        }
        let read = |name: &str| metadata_row(&conn, name).map_err(|e| sqlite_error(path, e));
        if let Some(format) = read("format")? {
            if !ACCEPTED_FORMATS.contains(&format.as_str()) {
                return Err(unusable(format!(
                    "holds tiles of format `{format}`, not quantized-mesh terrain (`{}`)",
                    ACCEPTED_FORMATS.join("` or `")
                )));
            }
        }
        let recorded_encoding = match read(ENCODING_ROW)?.as_deref() {
            Some("gzip") => Some(TileEncoding::Gzip),
            Some("identity") => Some(TileEncoding::Identity),
            _ => None,
        };
        Ok(MbtilesStore {
            db: Mutex::new(Db {
                conn,
                writes: 0,
                encodings_put: 0,
            }),
            path: path.to_path_buf(),
            staged: None,
            recorded_encoding,
        })
    }

    /// The file: the target of a store being built, or the file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Sets metadata row `name` to `value` (e.g. `name`, `description`, `attribution`),
    /// replacing any; the rows [`MbtilesStore::commit`] fills in are then left as set.
    ///
    /// # Errors
    /// As [`TileStore::put_file`].
    pub fn set_metadata(&self, name: &str, value: &str) -> StoreResult<()> {
        self.write(|conn| {
            conn.prepare_cached("INSERT OR REPLACE INTO metadata (name, value) VALUES (?1, ?2)")?
                .execute(params![name, value])
                .map(drop)
        })
    }

    /// The value of metadata row `name`, or `None` when there is none.
    ///
    /// # Errors
    /// [`StoreError::Io`] when the database cannot be read.
    pub fn metadata(&self, name: &str) -> StoreResult<Option<String>> {
        metadata_row(&self.db().conn, name).map_err(|e| self.sqlite(e))
    }

    /// Completes the file and renames it over its target: fills in the metadata rows not
    /// set ([`MBTILES_FORMAT`], the name, the zoom range and bounds, the tiles' encoding),
    /// commits, syncs and renames. On failure the temporary is removed and the target
    /// left as it was.
    ///
    /// # Errors
    /// [`StoreError::Unusable`] for a store opened for reading; [`StoreError::Io`] when
    /// the database cannot be completed, synced or renamed.
    pub fn commit(self) -> StoreResult<()> {
        let MbtilesStore {
            db, path, staged, ..
        } = self;
        let Some(staged) = staged else {
            return Err(read_only(&path));
        };
        let db = db
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let sqlite = |e| sqlite_error(&path, e);
        fill_metadata(&db, &path).map_err(sqlite)?;
        if !db.conn.is_autocommit() {
            db.conn.execute_batch("COMMIT").map_err(sqlite)?;
        }
        db.conn.close().map_err(|(_, e)| sqlite(e))?;
        let io = |source| StoreError::Io {
            location: path.display().to_string(),
            source,
        };
        staged.file().sync_all().map_err(io)?;
        staged.commit().map_err(io)
    }

    fn db(&self) -> MutexGuard<'_, Db> {
        self.db
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    fn sqlite(&self, e: rusqlite::Error) -> StoreError {
        sqlite_error(&self.path, e)
    }

    /// Runs `write` inside the open transaction (opening one when none is), and commits
    /// every [`WRITES_PER_TRANSACTION`] writes; fails on a store opened for reading.
    fn write<T>(&self, write: impl FnOnce(&Connection) -> rusqlite::Result<T>) -> StoreResult<T> {
        if self.staged.is_none() {
            return Err(read_only(&self.path));
        }
        let mut db = self.db();
        if db.conn.is_autocommit() {
            db.conn.execute_batch("BEGIN").map_err(|e| self.sqlite(e))?;
            db.writes = 0;
        }
        let value = write(&db.conn).map_err(|e| self.sqlite(e))?;
        db.writes += 1;
        if db.writes >= WRITES_PER_TRANSACTION {
            db.conn
                .execute_batch("COMMIT")
                .map_err(|e| self.sqlite(e))?;
            db.writes = 0;
        }
        Ok(value)
    }
}

impl TileStore for MbtilesStore {
    fn location(&self) -> String {
        self.path.display().to_string()
    }

    fn put_tile(
        &self,
        z: u8,
        x: u32,
        y: u32,
        bytes: &[u8],
        encoding: TileEncoding,
    ) -> StoreResult<()> {
        self.write(|conn| {
            conn.prepare_cached(
                "INSERT OR REPLACE INTO tiles (zoom_level, tile_column, tile_row, tile_data) \
                 VALUES (?1, ?2, ?3, ?4)",
            )?
            .execute(params![z, x, y, bytes])
            .map(drop)
        })?;
        self.db().encodings_put |= match encoding {
            TileEncoding::Gzip => 1,
            TileEncoding::Identity => 2,
        };
        Ok(())
    }

    fn get_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<Option<Vec<u8>>> {
        let db = self.db();
        let mut statement = db
            .conn
            .prepare_cached(
                "SELECT tile_data FROM tiles \
                 WHERE zoom_level = ?1 AND tile_column = ?2 AND tile_row = ?3",
            )
            .map_err(|e| self.sqlite(e))?;
        statement
            .query_row(params![z, x, y], |row| Ok(bytes_of(row.get_ref(0)?)))
            .optional()
            .map(Option::flatten)
            .map_err(|e| self.sqlite(e))
    }

    fn get_tile_encoded(
        &self,
        z: u8,
        x: u32,
        y: u32,
    ) -> StoreResult<Option<(Vec<u8>, TileEncoding)>> {
        let recorded = match self.staged {
            Some(_) => match self.db().encodings_put {
                1 => Some(TileEncoding::Gzip),
                2 => Some(TileEncoding::Identity),
                _ => None,
            },
            None => self.recorded_encoding,
        };
        Ok(self.get_tile(z, x, y)?.map(|bytes| {
            let encoding = recorded.unwrap_or_else(|| detect_encoding(&bytes));
            (bytes, encoding)
        }))
    }

    fn delete_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<()> {
        self.write(|conn| {
            conn.prepare_cached(
                "DELETE FROM tiles WHERE zoom_level = ?1 AND tile_column = ?2 AND tile_row = ?3",
            )?
            .execute(params![z, x, y])
            .map(drop)
        })
    }

    fn put_file(&self, name: &str, bytes: &[u8]) -> StoreResult<()> {
        check_file_name(name)?;
        match std::str::from_utf8(bytes) {
            Ok(text) if name == "layer.json" => self.set_metadata(&file_row(name), text),
            _ => self.write(|conn| {
                conn.execute_batch(FILES_TABLE)?;
                conn.prepare_cached(
                    "INSERT OR REPLACE INTO tinsmith_files (name, data) VALUES (?1, ?2)",
                )?
                .execute(params![name, bytes])
                .map(drop)
            }),
        }
    }

    fn get_file(&self, name: &str) -> StoreResult<Option<Vec<u8>>> {
        check_file_name(name)?;
        if name == "layer.json" {
            return Ok(self.metadata(&file_row(name))?.map(String::into_bytes));
        }
        let db = self.db();
        if !has_table(&db.conn, "tinsmith_files").map_err(|e| self.sqlite(e))? {
            return Ok(None);
        }
        db.conn
            .prepare_cached("SELECT data FROM tinsmith_files WHERE name = ?1")
            .and_then(|mut s| {
                s.query_row([name], |row| Ok(bytes_of(row.get_ref(0)?)))
                    .optional()
                    .map(Option::flatten)
            })
            .map_err(|e| self.sqlite(e))
    }

    fn delete_file(&self, name: &str) -> StoreResult<()> {
        check_file_name(name)?;
        let row = file_row(name);
        self.write(|conn| {
            conn.execute_batch(FILES_TABLE)?;
            conn.prepare_cached("DELETE FROM tinsmith_files WHERE name = ?1")?
                .execute([name])?;
            conn.prepare_cached("DELETE FROM metadata WHERE name = ?1")?
                .execute([row])
                .map(drop)
        })
    }

    fn list_files(&self, prefix: &str) -> StoreResult<Vec<String>> {
        let db = self.db();
        let mut statement = db
            .conn
            .prepare_cached("SELECT name FROM metadata")
            .map_err(|e| self.sqlite(e))?;
        let rows = statement
            .query_map([], |row| row.get::<_, Option<String>>(0))
            .map_err(|e| self.sqlite(e))?;
        let mut names = Vec::new();
        for row in rows {
            let Some(row) = row.map_err(|e| self.sqlite(e))? else {
                continue;
            };
            if let Some(name) = file_of_row(&row).filter(|n| n.starts_with(prefix)) {
                names.push(name.to_owned());
            }
        }
        drop(statement);
        if has_table(&db.conn, "tinsmith_files").map_err(|e| self.sqlite(e))? {
            let mut statement = db
                .conn
                .prepare_cached("SELECT name FROM tinsmith_files")
                .map_err(|e| self.sqlite(e))?;
            let rows = statement
                .query_map([], |row| row.get::<_, String>(0))
                .map_err(|e| self.sqlite(e))?;
            for row in rows {
                let name = row.map_err(|e| self.sqlite(e))?;
                if name.starts_with(prefix) {
                    names.push(name);
                }
            }
        }
        names.sort();
        Ok(names)
    }
}

/// The metadata row that holds file `name`.
fn file_row(name: &str) -> String {
    if name == "layer.json" {
        LAYER_JSON_ROW.to_owned()
    } else {
        format!("{FILE_ROW_PREFIX}{name}")
    }
}

/// The file metadata row `row` holds, if it holds one.
fn file_of_row(row: &str) -> Option<&str> {
    if row == LAYER_JSON_ROW {
        Some("layer.json")
    } else {
        row.strip_prefix(FILE_ROW_PREFIX)
            .filter(|name| check_file_name(name).is_ok())
    }
}

/// A blob's bytes (or a text's, as another tool may have stored a tile); `None` for NULL.
fn bytes_of(value: ValueRef<'_>) -> Option<Vec<u8>> {
    match value {
        ValueRef::Blob(bytes) | ValueRef::Text(bytes) => Some(bytes.to_vec()),
        _ => None,
    }
}

fn metadata_row(conn: &Connection, name: &str) -> rusqlite::Result<Option<String>> {
    conn.prepare_cached("SELECT value FROM metadata WHERE name = ?1")?
        .query_row([name], |row| {
            Ok(bytes_of(row.get_ref(0)?).map(|b| String::from_utf8_lossy(&b).into_owned()))
        })
        .optional()
        .map(Option::flatten)
}

/// Adds the rows every file gets, where they are not set: `format`, `name`, `minzoom`,
/// `maxzoom`, `bounds`; and `content_encoding` from the tiles put.
fn fill_metadata(db: &Db, path: &Path) -> rusqlite::Result<()> {
    let conn = &db.conn;
    let mut rows: Vec<(&str, String)> = vec![("format", MBTILES_FORMAT.to_owned())];
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    rows.push(("name", stem.unwrap_or_else(|| "terrain".into())));
    let zooms: (Option<i64>, Option<i64>) = conn.query_row(
        "SELECT MIN(zoom_level), MAX(zoom_level) FROM tiles",
        [],
        |r| Ok((r.get(0)?, r.get(1)?)),
    )?;
    if let (Some(min), Some(max)) = zooms {
        rows.push(("minzoom", min.to_string()));
        rows.push(("maxzoom", max.to_string()));
    }
    if let Some(bounds) = metadata_row(conn, LAYER_JSON_ROW)?
        .as_deref()
        .and_then(layer_bounds)
    {
        rows.push(("bounds", bounds));
    }
    for (name, value) in rows {
        conn.execute(
            "INSERT OR IGNORE INTO metadata (name, value) VALUES (?1, ?2)",
            params![name, value],
        )?;
    }
    let encoding = match db.encodings_put {
        1 => Some("gzip"),
        2 => Some("identity"),
        _ => None,
    };
    match encoding {
        Some(value) => conn.execute(
            "INSERT OR REPLACE INTO metadata (name, value) VALUES (?1, ?2)",
            params![ENCODING_ROW, value],
        )?,
        None => conn.execute("DELETE FROM metadata WHERE name = ?1", [ENCODING_ROW])?,
    };
    Ok(())
}

/// `layer.json`'s `bounds` ([west, south, east, north] in degrees) as MBTiles writes them.
fn layer_bounds(layer: &str) -> Option<String> {
    let layer: serde_json::Value = serde_json::from_str(layer).ok()?;
    let bounds = layer.get("bounds")?.as_array()?;
    let numbers: Vec<f64> = bounds
        .iter()
        .filter_map(serde_json::Value::as_f64)
        .collect();
    (numbers.len() == 4 && bounds.len() == 4).then(|| {
        numbers
            .iter()
            .map(f64::to_string)
            .collect::<Vec<_>>()
            .join(",")
    })
}

fn read_only(path: &Path) -> StoreError {
    StoreError::Unusable {
        location: path.display().to_string(),
        reason: "the MBTiles file was opened for reading".into(),
    }
}

/// An SQLite failure on the file at `path`, as an I/O error naming it.
fn sqlite_error(path: &Path, e: rusqlite::Error) -> StoreError {
    StoreError::Io {
        location: path.display().to_string(),
        source: std::io::Error::other(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        encoder.write_all(bytes).unwrap();
        encoder.finish().unwrap()
    }

    const LAYER: &str = r#"{"format":"quantized-mesh-1.0","bounds":[-122.5,37.25,-122,37.75]}"#;

    #[test]
    fn tiles_and_files_round_trip_and_appear_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("terrain.mbtiles");
        let store = MbtilesStore::create(&path).unwrap();
        let (a, b) = (gzip(b"tile a"), gzip(b"tile b"));
        store.put_tile(3, 1, 2, &a, TileEncoding::Gzip).unwrap();
        store.put_tile(5, 9, 7, &b, TileEncoding::Gzip).unwrap();
        store
            .put_tile(4, 0, 0, b"gone", TileEncoding::Gzip)
            .unwrap();
        store.delete_tile(4, 0, 0).unwrap();
        store.delete_tile(4, 0, 0).unwrap();
        // Overwritten: the last put wins.
        store.put_tile(3, 1, 2, &b, TileEncoding::Gzip).unwrap();
        assert_eq!(store.get_tile(3, 1, 2).unwrap(), Some(b.clone()));
        assert_eq!(store.get_tile(4, 0, 0).unwrap(), None);
        store.put_file("layer.json", b"{}").unwrap();
        store.put_file("layer.json", LAYER.as_bytes()).unwrap();
        store.put_file("shards/2-of-7.json", b"[2]").unwrap();
        store.put_file("shards/1-of-7.json", b"[1]").unwrap();
        assert_eq!(
            store.list_files("").unwrap(),
            ["layer.json", "shards/1-of-7.json", "shards/2-of-7.json"]
        );
        assert_eq!(
            store.list_files("shards/").unwrap(),
            ["shards/1-of-7.json", "shards/2-of-7.json"]
        );
        assert_eq!(store.get_file("nope.json").unwrap(), None);
        assert!(store.put_file("../x", b"").is_err());
        // Binary files (a block's samples) too, and deletes.
        store.put_file("bin", &[0xff, 0xfe]).unwrap();
        assert_eq!(store.get_file("bin").unwrap(), Some(vec![0xff, 0xfe]));
        store.delete_file("bin").unwrap();
        assert_eq!(store.get_file("bin").unwrap(), None);
        // Nothing at the target yet: only the locked temporary beside it.
        assert!(!path.exists());
        let names = entries(dir.path());
        assert_eq!(names.len(), 1);
        assert!(names[0].starts_with(".tinsmith-") && names[0].ends_with(".tmp"));
        store.commit().unwrap();
        assert_eq!(entries(dir.path()), ["terrain.mbtiles"]);

        let read = MbtilesStore::open(&path).unwrap();
        assert_eq!(read.get_tile(3, 1, 2).unwrap(), Some(b.clone()));
        assert_eq!(read.get_tile(5, 9, 7).unwrap(), Some(b.clone()));
        assert_eq!(read.get_tile(4, 0, 0).unwrap(), None);
        assert_eq!(
            read.get_tile_encoded(5, 9, 7).unwrap(),
            Some((b, TileEncoding::Gzip))
        );
        assert_eq!(
            read.get_file("layer.json").unwrap().as_deref(),
            Some(LAYER.as_bytes())
        );
        assert_eq!(
            read.get_file("shards/1-of-7.json").unwrap().as_deref(),
            Some(&b"[1]"[..])
        );
        assert_eq!(read.list_files("").unwrap().len(), 3);
        let row = |name| read.metadata(name).unwrap();
        assert_eq!(row("format").as_deref(), Some(MBTILES_FORMAT));
        assert_eq!(row("name").as_deref(), Some("terrain"));
        assert_eq!(row("minzoom").as_deref(), Some("3"));
        assert_eq!(row("maxzoom").as_deref(), Some("5"));
        assert_eq!(row("bounds").as_deref(), Some("-122.5,37.25,-122,37.75"));
        assert_eq!(row("json").as_deref(), Some(LAYER));
        assert_eq!(row("content_encoding").as_deref(), Some("gzip"));
        // Opened for reading: writes are refused, naming the file.
        let err = read
            .put_tile(0, 0, 0, b"x", TileEncoding::Gzip)
            .unwrap_err();
        assert!(err.to_string().contains("terrain.mbtiles"), "{err}");
        assert!(read.put_file("a.json", b"{}").is_err());
        assert!(read.commit().is_err());
        assert_eq!(entries(dir.path()), ["terrain.mbtiles"]);
    }

    #[test]
    fn dropped_without_commit_it_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.mbtiles");
        std::fs::write(&path, b"the previous file").unwrap();
        let store = MbtilesStore::create(&path).unwrap();
        for i in 0..5000 {
            store
                .put_tile(12, i, 7, b"data", TileEncoding::Identity)
                .unwrap();
        }
        drop(store);
        assert_eq!(std::fs::read(&path).unwrap(), b"the previous file");
        assert_eq!(entries(dir.path()), ["t.mbtiles"]);

        // Committed, it replaces the file whole.
        let store = MbtilesStore::create(&path).unwrap();
        store.set_metadata("name", "Bay Area").unwrap();
        store
            .put_tile(1, 1, 0, b"plain", TileEncoding::Identity)
            .unwrap();
        store.commit().unwrap();
        let read = MbtilesStore::open(&path).unwrap();
        assert_eq!(read.metadata("name").unwrap().as_deref(), Some("Bay Area"));
        assert_eq!(
            read.metadata("content_encoding").unwrap().as_deref(),
            Some("identity")
        );
        assert_eq!(read.metadata("bounds").unwrap(), None);
        assert_eq!(entries(dir.path()), ["t.mbtiles"]);
    }

    #[test]
    fn mixed_encodings_are_read_from_the_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mixed.mbtiles");
        let store = MbtilesStore::create(&path).unwrap();
        let zipped = gzip(b"zipped");
        // A plain tile whose first bytes look like gzip's header.
        let plain = [0x1f, 0x8b, 0x08, 0x00, 1, 2, 3, 4, 5, 6, 7, 8];
        store
            .put_tile(2, 0, 0, &zipped, TileEncoding::Gzip)
            .unwrap();
        store
            .put_tile(2, 1, 0, &plain, TileEncoding::Identity)
            .unwrap();
        store.commit().unwrap();
        let read = MbtilesStore::open(&path).unwrap();
        assert_eq!(read.metadata("content_encoding").unwrap(), None);
        let encoding = |x| read.get_tile_encoded(2, x, 0).unwrap().unwrap().1;
        assert_eq!(encoding(0), TileEncoding::Gzip);
        assert_eq!(encoding(1), TileEncoding::Identity);
    }

    #[test]
    fn threads_share_one_store() {
        fn shared<T: Send + Sync>(_: &T) {}
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.mbtiles");
        let store = MbtilesStore::create(&path).unwrap();
        shared(&store);
        std::thread::scope(|s| {
            for t in 0..4u32 {
                let store = &store;
                s.spawn(move || {
                    for i in 0..3000u32 {
                        let bytes = (t * 10_000 + i).to_le_bytes();
                        store
                            .put_tile(14, t, i, &bytes, TileEncoding::Identity)
                            .unwrap();
                    }
                });
            }
        });
        store.commit().unwrap();
        let read = MbtilesStore::open(&path).unwrap();
        for t in 0..4u32 {
            for i in [0, 1234, 2999] {
                let want = (t * 10_000 + i).to_le_bytes().to_vec();
                assert_eq!(read.get_tile(14, t, i).unwrap(), Some(want));
            }
        }
        assert_eq!(read.metadata("maxzoom").unwrap().as_deref(), Some("14"));
    }

    #[test]
    fn files_that_are_not_quantized_mesh_mbtiles_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let message = |path: &Path| {
            let err = MbtilesStore::open(path).unwrap_err();
            let text = err.to_string();
            assert!(text.contains(&path.display().to_string()), "{text}");
            text
        };
        let missing = dir.path().join("missing.mbtiles");
        assert!(message(&missing).contains("No such file"));
        assert!(message(dir.path()).contains("not a file"));
        let text = dir.path().join("notes.mbtiles");
        std::fs::write(
            &text,
            "not a database, only some text long enough to be read",
        )
        .unwrap();
        assert!(message(&text).contains("not an SQLite database"));
        let other = dir.path().join("other.mbtiles");
        Connection::open(&other)
            .unwrap()
            .execute_batch("CREATE TABLE tiles (a, b)")
            .unwrap();
        assert!(message(&other).contains("not an MBTiles file"));
        let png = dir.path().join("png.mbtiles");
        let store = MbtilesStore::create(&png).unwrap();
        store.set_metadata("format", "png").unwrap();
        store.commit().unwrap();
        assert!(message(&png).contains("format `png`"));
        // Nothing was written beside them.
        assert_eq!(
            entries(dir.path()),
            ["notes.mbtiles", "other.mbtiles", "png.mbtiles"]
        );
        assert!(MbtilesStore::create(dir.path()).is_err());
    }
}
