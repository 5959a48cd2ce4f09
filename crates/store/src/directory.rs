//! A pyramid in a local directory: `{z}/{x}/{y}.terrain` files and named files, each
//! written through a temporary file renamed into place.

use std::path::{Path, PathBuf};

use crate::{check_file_name, tile_key, StoreError, StoreResult, TileEncoding, TileStore};

/// A directory on the local file system. Tiles are files whatever their encoding (a web
/// server must add `Content-Encoding: gzip` itself, as `tinsmith serve` does).
#[derive(Debug, Clone)]
pub struct DirectoryStore {
    root: PathBuf,
}

impl DirectoryStore {
    /// A store rooted at `root`, which must be a directory (made, with its parents, when
    /// missing).
    ///
    /// # Errors
    /// [`StoreError::Io`] when the directory cannot be made, [`StoreError::Unusable`] when
    /// `root` exists and is not a directory.
    pub fn open(root: &Path) -> StoreResult<DirectoryStore> {
        if root.exists() && !root.is_dir() {
            return Err(StoreError::Unusable {
                location: root.display().to_string(),
                reason: "exists and is not a directory".into(),
            });
        }
        std::fs::create_dir_all(root).map_err(|source| StoreError::Io {
            location: root.display().to_string(),
            source,
        })?;
        Ok(DirectoryStore {
            root: root.to_path_buf(),
        })
    }

    /// The directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    fn write(&self, key: &str, bytes: &[u8]) -> StoreResult<()> {
        let path = self.root.join(key);
        let io = |source| StoreError::Io {
            location: path.display().to_string(),
            source,
        };
        // A removal beside this write may take its directory, or one above it, away while
        // empty (see `remove`), between making it and writing: made again, up to
        // `WRITE_ATTEMPTS` times.
        let vanished = |e: &std::io::Error| e.kind() == std::io::ErrorKind::NotFound;
        let mut attempt = 1;
        loop {
            let made = match path.parent() {
                Some(parent) => std::fs::create_dir_all(parent),
                None => Ok(()),
            };
            let written = made.and_then(|()| tinsmith_output::write_bytes_atomically(&path, bytes));
            match written {
                Err(e) if vanished(&e) && attempt < WRITE_ATTEMPTS => attempt += 1,
                result => return result.map_err(io),
            }
        }
    }

    /// Removes the file at `key`, and the directories above it that it leaves empty (a
    /// level's or a column's last tile), so that an updated pyramid's tree is a fresh
    /// build's.
    fn remove(&self, key: &str) -> StoreResult<()> {
        let path = self.root.join(key);
        match std::fs::remove_file(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(source) => {
                return Err(StoreError::Io {
                    location: path.display().to_string(),
                    source,
                })
            }
        }
        // `remove_dir` takes only an empty directory; any other outcome ends the walk.
        let mut dir = path.parent();
        while let Some(d) = dir.filter(|d| *d != self.root && d.starts_with(&self.root)) {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
            dir = d.parent();
        }
        Ok(())
    }

    fn read(&self, key: &str) -> StoreResult<Option<Vec<u8>>> {
        let path = self.root.join(key);
        match std::fs::read(&path) {
            Ok(bytes) => Ok(Some(bytes)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(source) => Err(StoreError::Io {
                location: path.display().to_string(),
                source,
            }),
        }
    }
}

/// How many times a write makes its directories and writes, when a removal beside it
/// takes a directory away in between (each time needs another removal to empty it).
const WRITE_ATTEMPTS: u32 = 16;

impl TileStore for DirectoryStore {
    fn location(&self) -> String {
        self.root.display().to_string()
    }

    fn put_tile(
        &self,
        z: u8,
        x: u32,
        y: u32,
        bytes: &[u8],
        _encoding: TileEncoding,
    ) -> StoreResult<()> {
        self.write(&tile_key(z, x, y), bytes)
    }

    fn get_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<Option<Vec<u8>>> {
        self.read(&tile_key(z, x, y))
    }

    fn delete_tile(&self, z: u8, x: u32, y: u32) -> StoreResult<()> {
        self.remove(&tile_key(z, x, y))
    }

    fn delete_file(&self, name: &str) -> StoreResult<()> {
        check_file_name(name)?;
        self.remove(name)
    }

    fn put_file(&self, name: &str, bytes: &[u8]) -> StoreResult<()> {
        check_file_name(name)?;
        self.write(name, bytes)
    }

    fn get_file(&self, name: &str) -> StoreResult<Option<Vec<u8>>> {
        check_file_name(name)?;
        self.read(name)
    }

    fn list_files(&self, prefix: &str) -> StoreResult<Vec<String>> {
        // The directory part of the prefix, then names under it.
        let (dir, _) = prefix.rsplit_once('/').unwrap_or(("", prefix));
        let base = self.root.join(dir);
        let mut out = Vec::new();
        let mut stack = vec![base.clone()];
        while let Some(d) = stack.pop() {
            let entries = match std::fs::read_dir(&d) {
                Ok(entries) => entries,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                Err(source) => {
                    return Err(StoreError::Io {
                        location: d.display().to_string(),
                        source,
                    })
                }
            };
            for entry in entries {
                let entry = entry.map_err(|source| StoreError::Io {
                    location: d.display().to_string(),
                    source,
                })?;
                let path = entry.path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                let Ok(relative) = path.strip_prefix(&self.root) else {
                    continue;
                };
                let name = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy())
                    .collect::<Vec<_>>()
                    .join("/");
                // Temporaries of writes in progress are not files yet.
                if name.starts_with(prefix) && !name.ends_with(".tmp") {
                    out.push(name);
                }
            }
        }
        out.sort();
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn puts_gets_lists_and_deletes() {
        let dir = tempfile::tempdir().unwrap();
        let store = DirectoryStore::open(&dir.path().join("p")).unwrap();
        assert_eq!(store.get_tile(3, 1, 2).unwrap(), None);
        store.put_tile(3, 1, 2, b"abc", TileEncoding::Gzip).unwrap();
        assert_eq!(
            store.get_tile(3, 1, 2).unwrap().as_deref(),
            Some(&b"abc"[..])
        );
        assert!(dir.path().join("p/3/1/2.terrain").is_file());
        store.put_file("shards/2-of-7.json", b"{}").unwrap();
        store.put_file("shards/1-of-7.json", b"{}").unwrap();
        store.put_file("layer.json", b"{}").unwrap();
        assert_eq!(
            store.list_files("shards/").unwrap(),
            ["shards/1-of-7.json", "shards/2-of-7.json"]
        );
        store.delete_tile(3, 1, 2).unwrap();
        store.delete_tile(3, 1, 2).unwrap();
        store.delete_file("shards/1-of-7.json").unwrap();
        assert_eq!(store.list_files("shards/").unwrap(), ["shards/2-of-7.json"]);
        assert_eq!(store.get_tile(3, 1, 2).unwrap(), None);
        assert!(store.put_file("../x", b"").is_err());
        assert!(store.put_file("/x", b"").is_err());
    }
}
