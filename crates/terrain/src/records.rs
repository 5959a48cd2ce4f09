//! What a pyramid keeps about how each tile was made, under `tinsmith/` beside its tiles,
//! so that a re-run (a shard interrupted, an input updated) rebuilds only the tiles whose
//! data changed:
//! - `tinsmith/blocks/{x}-{y}.json`: each tile of a block (a tile of the split level and
//!   the tiles under it): the fingerprint of the data it was built from, whether it was
//!   written, and its counts; `{x}-{y}.samples` holds the block's samples at the split
//!   level (gzipped little-endian f32), what the levels above are filtered from.
//! - `tinsmith/top.json`: the same for the levels above the blocks and the flat roots.
//! - `tinsmith/shards/{i}-of-{n}.json`: a shard's plan and blocks (sharded runs).
//!
//! Records are written after the tiles they describe, so a record never claims a tile
//! that is not in place.

use std::collections::HashMap;
use std::io::{Read, Write};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::plan::{Plan, Shard};
use crate::{LevelReport, TerrainError, TerrainOptions, TerrainResult};
use tinsmith_store::TileStore;

/// Where the records live, relative to the pyramid.
pub(super) const RECORDS_DIR: &str = "tinsmith";

/// One tile as a run left it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct TileEntry {
    pub(super) z: u8,
    pub(super) x: u32,
    pub(super) y: u32,
    /// Fingerprint of everything the tile was built from (hex).
    pub(super) sum: String,
    /// Whether it was written (a tile without a valid cell is not).
    pub(super) written: bool,
    pub(super) bytes: u64,
    pub(super) vertices: u64,
    pub(super) triangles: u64,
    pub(super) max_error: f64,
    pub(super) verified_bound: f64,
    /// 3D Tiles: the metadata its subtree gives it (absent for quantized-mesh), so that a
    /// run that keeps the tile (an update, a shard's merge) writes the same subtrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) bounds: Option<crate::TileBounds>,
}

/// Tiles by (level, column, TMS row).
pub(super) type Entries = HashMap<(u8, u32, u32), TileEntry>;

/// The fingerprint of a tile: a hash of the options that shape tiles, its address, the
/// data it reads (fed by `feed`) and its metadata extension.
pub(super) fn tile_sum(
    options_key: &str,
    (z, x, y): (u8, u32, u32),
    metadata: Option<&str>,
    feed: impl FnOnce(&mut Sha256),
) -> String {
    let mut hash = Sha256::new();
    hash.update(options_key.as_bytes());
    hash.update([z]);
    hash.update(x.to_le_bytes());
    hash.update(y.to_le_bytes());
    hash.update(metadata.unwrap_or("").as_bytes());
    feed(&mut hash);
    hex(&hash.finalize()[..16])
}

/// The key of the options that shape tiles' bytes (not the zoom range).
pub(super) fn options_key(options: &TerrainOptions) -> String {
    let mut text = serde_json::json!({
        "band": options.band, "quality": options.quality, "normals": options.normals,
        "metadata": options.metadata, "gzip": options.gzip, "format": 1,
    });
    // Tiles gzipped by libdeflate since it replaced zlib: an update rebuilds a pyramid
    // gzipped before, so that it equals a fresh build byte for byte.
    if options.gzip {
        text["gzip_by"] = "libdeflate 10".into();
    }
    // Normals at longitudes counted round the globe since they came from each tile's
    // west edge: an update rebuilds a pyramid with normals built before.
    if options.normals {
        text["normals_at"] = "lattice longitudes".into();
    }
    // Coarse tiles' edges measured on the globe since they replaced lattice spacings, and
    // every level's triangles facing outwards there: an update rebuilds a pyramid built
    // before either, so that shared edges agree.
    text["edges"] = "globe, faces".into();
    // Absent for the ellipsoid, so that pyramids built before datums were chosen keep
    // their key.
    if options.vertical_datum != tinsmith_raster::VerticalDatum::Ellipsoid {
        text["vertical_datum"] = options.vertical_datum.label().into();
    }
    if let Some(water) = &options.water {
        text["water"] = water.label().into();
    }
    if options.whole_globe {
        text["whole_globe"] = true.into();
    }
    if let Some(base) = &options.base {
        text["base"] = base.path.to_string_lossy().into();
        text["base_vertical_datum"] = base.vertical_datum.label().into();
    }
    if options.format != crate::TileFormat::QuantizedMesh {
        text["tile_format"] = options.format.label().into();
    }
    // Absent for the geographic tiling, so that its pyramids keep their key.
    if options.tiling != crate::tms::Tiling::Geographic {
        text["tiling"] = options.tiling.name().into();
    }
    hex(&Sha256::digest(text.to_string().as_bytes()))
}

/// Lower-case hexadecimal.
pub(super) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// What one block built.
#[derive(Debug, Serialize, Deserialize)]
pub(super) struct BlockRecord {
    /// [`options_key`] of the run.
    pub(super) options: String,
    /// The block: column, TMS row (of the split level).
    pub(super) block: [u32; 2],
    pub(super) split: u8,
    pub(super) tiles: Vec<TileEntry>,
    /// Whether the block has samples at the split level (a `.samples` file).
    pub(super) samples: bool,
}

/// What the levels above the blocks (and the flat roots) built.
#[derive(Debug, Serialize, Deserialize)]
pub(super) struct TopRecord {
    pub(super) options: String,
    pub(super) tiles: Vec<TileEntry>,
}

/// What a shard built.
#[derive(Debug, Serialize, Deserialize)]
pub(super) struct ShardRecord {
    /// [`Plan::id`].
    pub(super) plan_id: String,
    pub(super) plan: Plan,
    pub(super) shard: Shard,
    /// Its blocks: column, TMS row.
    pub(super) blocks: Vec<[u32; 2]>,
}

pub(super) fn block_name(split: u8, block: [u32; 2]) -> String {
    format!("{RECORDS_DIR}/blocks/{split}-{}-{}", block[0], block[1])
}

pub(super) fn shard_name(shard: Shard) -> String {
    format!(
        "{RECORDS_DIR}/shards/{}-of-{}.json",
        shard.index, shard.count
    )
}

pub(super) fn top_name() -> String {
    format!("{RECORDS_DIR}/top.json")
}

/// A JSON record `name` in `store`, or `None` when there is none.
pub(super) fn read_record<T: serde::de::DeserializeOwned>(
    store: &dyn TileStore,
    name: &str,
) -> TerrainResult<Option<T>> {
    let Some(bytes) = store.get_file(name)? else {
        return Ok(None);
    };
    serde_json::from_slice(&bytes).map(Some).map_err(|e| {
        TerrainError::Options(format!(
            "{}/{name}: not a record tinsmith wrote ({e}); remove {}/{RECORDS_DIR} to start \
             afresh",
            store.location(),
            store.location(),
        ))
    })
}

/// Writes a JSON record `name` into `store`.
pub(super) fn put_record<T: Serialize>(
    store: &dyn TileStore,
    name: &str,
    record: &T,
) -> TerrainResult<()> {
    let bytes = serde_json::to_vec(record).expect("a record serializes");
    Ok(store.put_file(name, &bytes)?)
}

/// A block's samples, gzipped.
pub(super) fn gzip_samples(values: &[f32]) -> Vec<u8> {
    // One write: the encoder does a compression step per write, which for 4-byte writes
    // cost more than the rest of a shard's bookkeeping.
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(&bytes).expect("writing to memory");
    e.finish().expect("writing to memory")
}

/// A block's samples from file `name` of `store`.
pub(super) fn read_samples(
    store: &dyn TileStore,
    name: &str,
    cells: u32,
) -> TerrainResult<Vec<f32>> {
    let bad = |reason: String| {
        TerrainError::Options(format!(
            "{}/{name}: not a block's samples ({reason}); re-run the shard that built it",
            store.location()
        ))
    };
    let bytes = store.get_file(name)?.ok_or_else(|| bad("missing".into()))?;
    let side = cells as usize + 1;
    let mut raw = Vec::new();
    flate2::read::GzDecoder::new(&bytes[..])
        .read_to_end(&mut raw)
        .map_err(|e| bad(e.to_string()))?;
    if raw.len() != side * side * 4 {
        return Err(bad(format!("{} bytes", raw.len())));
    }
    Ok(raw
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Adds `entry`'s counts to `report` (its level's).
pub(super) fn count(report: &mut LevelReport, entry: &TileEntry) {
    if entry.written {
        report.tiles += 1;
        report.bytes += entry.bytes;
        report.vertices += entry.vertices;
        report.triangles += entry.triangles;
        report.measured_max_error = report.measured_max_error.max(entry.max_error);
        report.achieved_bound = report.achieved_bound.max(entry.verified_bound);
    } else {
        report.empty_tiles += 1;
    }
}
