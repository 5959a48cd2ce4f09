//! A pyramid built in shards on many machines: each shard builds its blocks into a shared
//! destination and records what it built; the merge checks that every shard of one plan
//! is there, builds the levels above the blocks from the blocks' samples, and writes
//! `layer.json` last, so a pyramid appears only when it is complete. The tiles are those
//! of a one-process run, byte for byte (see [`crate::build_terrain`]).
//!
//! Records, beside the tiles:
//! - `shards/blocks/{x}-{y}.json` and `.samples`: a block's tiles and level counts, and
//!   its samples at the split level (gzipped little-endian f32). Written after the
//!   block's tiles, so a record means the block is complete; a re-run skips it.
//! - `shards/{i}-of-{n}.json`: the plan and the shard's blocks, written after them all.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::blocks::SplitSamples;
use crate::layer::write_layer_json;
use crate::plan::{Plan, Shard, TileOptions};
use crate::pyramid::{
    build_block, build_top, level_reports, prepare, worker_pool, write_atomic, write_flat_roots,
    Prepared,
};
use crate::stream::Warp;
use crate::tms::{bounds_array, tile_column, TileRect, TILE_CELLS};
use crate::writer::Written;
use crate::{LevelReport, TerrainError, TerrainOptions, TerrainReport, TerrainResult};

/// What one block built, as its record keeps it.
#[derive(Debug, Serialize, Deserialize)]
struct BlockRecord {
    /// [`Plan::block_key`] of the plan it was built under.
    key: String,
    /// The block: column, TMS row.
    block: [u32; 2],
    /// Tiles written: level, column, TMS row.
    tiles: Vec<[u32; 3]>,
    /// Per level written, its counts.
    levels: Vec<LevelReport>,
    /// Whether the block has samples at the split level (a `.samples` file).
    samples: bool,
}

/// What a shard built, as its record keeps it.
#[derive(Debug, Serialize, Deserialize)]
struct ShardRecord {
    /// [`Plan::id`].
    plan_id: String,
    plan: Plan,
    shard: Shard,
    /// Its blocks: column, TMS row.
    blocks: Vec<[u32; 2]>,
}

/// What [`build_shard`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShardReport {
    /// The shard.
    pub shard: Shard,
    /// Its blocks.
    pub blocks: usize,
    /// Of them, done by an earlier run under the same plan and kept.
    pub blocks_kept: usize,
    /// Its blocks' valid samples of the coarse read (its share of the plan's work).
    pub weight: u64,
    /// The plan's total.
    pub total_weight: u64,
    /// Tiles it wrote (kept blocks included).
    pub tiles: u64,
    /// Per level it wrote, coarsest first.
    pub levels: Vec<LevelReport>,
}

fn block_name(block: [u32; 2]) -> String {
    format!("shards/blocks/{}-{}", block[0], block[1])
}

fn shard_name(shard: Shard) -> String {
    format!("shards/{}-of-{}.json", shard.index, shard.count)
}

fn read_optional(path: &Path) -> TerrainResult<Option<Vec<u8>>> {
    match std::fs::read(path) {
        Ok(bytes) => Ok(Some(bytes)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(source) => Err(TerrainError::Output {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// Writes `bytes` to `dest/name`, making the directories it needs.
fn put(dest: &Path, name: &str, bytes: &[u8]) -> TerrainResult<()> {
    let path = dest.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| TerrainError::Output {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    write_atomic(&path, bytes)
}

fn gzip_samples(values: &[f32]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    for v in values {
        e.write_all(&v.to_le_bytes()).expect("writing to memory");
    }
    e.finish().expect("writing to memory")
}

fn gunzip_samples(path: &Path, bytes: &[u8]) -> TerrainResult<Vec<f32>> {
    let side = TILE_CELLS as usize + 1;
    let mut raw = Vec::new();
    let bad = |reason: String| {
        TerrainError::Options(format!(
            "{}: not a block's samples ({reason})",
            path.display()
        ))
    };
    flate2::read::GzDecoder::new(bytes)
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

/// The block record at `dest` for `block`, if it is there and was built under `key`.
fn kept_block(dest: &Path, block: [u32; 2], key: &str) -> TerrainResult<Option<BlockRecord>> {
    let path = dest.join(format!("{}.json", block_name(block)));
    let Some(bytes) = read_optional(&path)? else {
        return Ok(None);
    };
    let record: BlockRecord = serde_json::from_slice(&bytes).map_err(|e| {
        TerrainError::Options(format!("{}: not a block record ({e})", path.display()))
    })?;
    Ok((record.key == key && record.block == block).then_some(record))
}

/// Builds shard `shard` of the pyramid of `input` into the directory `dest` (shared by
/// every shard; made when missing): the tiles of the shard's blocks, their records, then
/// the shard's record. Blocks already recorded under the same plan (an interrupted run of
/// this shard, or of any shard count) are kept, not rebuilt. `note` hears of each block.
///
/// # Errors
/// As [`crate::build_terrain`]; an existing shard record of another plan at `dest` is
/// replaced only when it is this shard's own name.
pub fn build_shard(
    input: &Path,
    dest: &Path,
    options: &TerrainOptions,
    shard: Shard,
    note: &mut dyn FnMut(&str),
) -> TerrainResult<ShardReport> {
    let start = std::time::Instant::now();
    let Prepared {
        bounds,
        own_level,
        max_zoom,
    } = prepare(input, options)?;
    if dest.exists() && !dest.is_dir() {
        return Err(TerrainError::Options(format!(
            "output {}: is not a directory",
            dest.display()
        )));
    }
    let plan = Plan::new(
        input,
        &bounds,
        own_level,
        TileOptions::new(options, max_zoom),
        shard.count,
    )?;
    let key = plan.block_key();
    let cut = plan.cut();
    let all = plan.blocks();
    let mine = plan.shard_blocks(shard.index);
    let total_weight: u64 = plan.weights.iter().sum();
    note(&format!(
        "shard {shard}: planned in {:.2} s: {} blocks at level {} (anchor {}), this shard's \
         {} of them, {:.2} % of the weight",
        start.elapsed().as_secs_f64(),
        all.len(),
        cut.split,
        cut.anchor,
        mine.len(),
        100.0 * plan.weights[mine.clone()].iter().sum::<u64>() as f64 / total_weight as f64
    ));
    let pool = worker_pool(&bounds, max_zoom.max(cut.anchor), options.threads)?;
    let source = Warp {
        path: input,
        band: options.band,
    };
    let mut written = Written::default();
    let mut kept = 0;
    let blocks: Vec<TileRect> = all[mine.clone()].to_vec();
    for (k, &block) in blocks.iter().enumerate() {
        let id = [tile_column(cut.split, block.x0), block.y0];
        if let Some(record) = kept_block(dest, id, &key)? {
            kept += 1;
            let mut done = Written::default();
            done.reports.resize(usize::from(max_zoom) + 1, None);
            done.available
                .resize(usize::from(max_zoom) + 1, Default::default());
            for level in record.levels {
                let z = usize::from(level.level);
                done.reports[z] = Some(level);
            }
            for [z, x, y] in record.tiles {
                done.available[z as usize].insert((x, y));
            }
            written.absorb(done);
            continue;
        }
        let (done, samples) = build_block(
            &source, &bounds, cut, max_zoom, block, None, dest, options, &pool,
        )?;
        if let Some(values) = &samples {
            put(
                dest,
                &format!("{}.samples", block_name(id)),
                &gzip_samples(values),
            )?;
        }
        let record = BlockRecord {
            key: key.clone(),
            block: id,
            tiles: done
                .available
                .iter()
                .enumerate()
                .flat_map(|(z, tiles)| tiles.iter().map(move |&(x, y)| [z as u32, x, y]))
                .collect(),
            levels: done.reports.iter().flatten().cloned().collect(),
            samples: samples.is_some(),
        };
        let json = serde_json::to_vec(&record).expect("a record serializes");
        put(dest, &format!("{}.json", block_name(id)), &json)?;
        written.absorb(done);
        note(&format!(
            "shard {shard}: block {} of {} ({}/{}/{}) done",
            k + 1,
            blocks.len(),
            cut.split,
            id[0],
            id[1]
        ));
    }
    let record = ShardRecord {
        plan_id: plan.id(),
        plan: plan.clone(),
        shard,
        blocks: blocks
            .iter()
            .map(|b| [tile_column(cut.split, b.x0), b.y0])
            .collect(),
    };
    let json = serde_json::to_vec_pretty(&record).expect("a record serializes");
    put(dest, &shard_name(shard), &json)?;
    let levels = level_reports(&written, options, max_zoom);
    Ok(ShardReport {
        shard,
        blocks: blocks.len(),
        blocks_kept: kept,
        weight: plan.weights[mine].iter().sum(),
        total_weight: plan.weights.iter().sum(),
        tiles: levels.iter().map(|l| l.tiles).sum(),
        levels,
    })
}

/// The shard records in `dest/shards`, by file.
fn shard_records(dest: &Path) -> TerrainResult<Vec<(PathBuf, ShardRecord)>> {
    let dir = dest.join("shards");
    let entries = match std::fs::read_dir(&dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(TerrainError::Options(format!(
                "{}: no shard records (shards/I-of-N.json); run `tinsmith tiles INPUT -o {} \
                 --shard I/N` for every I first",
                dest.display(),
                dest.display()
            )))
        }
        Err(source) => return Err(TerrainError::Output { path: dir, source }),
    };
    let mut out = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|source| TerrainError::Output {
                path: dir.clone(),
                source,
            })?
            .path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        if !name.is_some_and(|n| n.contains("-of-") && n.ends_with(".json")) {
            continue;
        }
        let bytes = std::fs::read(&path).map_err(|source| TerrainError::Output {
            path: path.clone(),
            source,
        })?;
        let record: ShardRecord = serde_json::from_slice(&bytes).map_err(|e| {
            TerrainError::Options(format!("{}: not a shard record ({e})", path.display()))
        })?;
        out.push((path, record));
    }
    out.sort_by_key(|(_, r)| r.shard.index);
    Ok(out)
}

/// Finishes a sharded pyramid in `dest`: checks that every shard of one plan is recorded,
/// builds the levels above the blocks and (with `--metadata`) the flat roots, and writes
/// `layer.json` last. Refuses, naming them, shards of different plans, missing shards, or
/// block records that do not match; then no `layer.json` is written.
pub fn merge_shards(
    dest: &Path,
    threads: usize,
    progress: &mut dyn FnMut(&LevelReport),
) -> TerrainResult<TerrainReport> {
    let records = shard_records(dest)?;
    let Some((first_path, first)) = records.first() else {
        return Err(TerrainError::Options(format!(
            "{}: no shard records in shards/; run the shards first",
            dest.display()
        )));
    };
    for (path, record) in &records {
        if record.plan_id != first.plan_id || record.plan_id != record.plan.id() {
            return Err(TerrainError::Options(format!(
                "{} and {} belong to different plans (input {} vs {}, {} vs {} shards, or \
                 other options): keep the shards of one run only",
                first_path.display(),
                path.display(),
                first.plan.input,
                record.plan.input,
                first.plan.shards,
                record.plan.shards
            )));
        }
    }
    let plan = &first.plan;
    let missing: Vec<String> = (0..plan.shards)
        .filter(|i| !records.iter().any(|(_, r)| r.shard.index == *i))
        .map(|i| format!("{i}/{}", plan.shards))
        .collect();
    if !missing.is_empty() {
        return Err(TerrainError::Options(format!(
            "{}: shard{} {} of the plan missing (no {}); no layer.json written",
            dest.display(),
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            missing
                .iter()
                .map(|m| m.replace('/', "-of-"))
                .map(|m| format!("shards/{m}.json"))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let options = plan.options.to_options(threads);
    let bounds = plan.bounds();
    let cut = plan.cut();
    let max_zoom = plan.options.max_zoom;
    let key = plan.block_key();
    let mut written = Written::default();
    written.reports.resize(usize::from(max_zoom) + 1, None);
    written
        .available
        .resize(usize::from(max_zoom) + 1, Default::default());
    let mut samples = SplitSamples::default();
    for (path, record) in &records {
        let expected: Vec<[u32; 2]> = plan.blocks()[plan.shard_blocks(record.shard.index)]
            .iter()
            .map(|b| [tile_column(cut.split, b.x0), b.y0])
            .collect();
        if record.blocks != expected {
            return Err(TerrainError::Options(format!(
                "{}: its blocks are not those its plan gives shard {}",
                path.display(),
                record.shard
            )));
        }
        for &block in &record.blocks {
            let Some(done) = kept_block(dest, block, &key)? else {
                return Err(TerrainError::Options(format!(
                    "{}: block record {}.json is missing or of another plan; re-run shard {}",
                    dest.display(),
                    block_name(block),
                    record.shard
                )));
            };
            let mut one = Written::default();
            one.reports.resize(usize::from(max_zoom) + 1, None);
            one.available
                .resize(usize::from(max_zoom) + 1, Default::default());
            for level in done.levels {
                let z = usize::from(level.level);
                one.reports[z] = Some(level);
            }
            for [z, x, y] in done.tiles {
                one.available[z as usize].insert((x, y));
            }
            written.absorb(one);
            if done.samples {
                let path = dest.join(format!("{}.samples", block_name(block)));
                let bytes = read_optional(&path)?
                    .ok_or_else(|| TerrainError::Options(format!("{}: missing", path.display())))?;
                samples
                    .tiles
                    .insert((block[0], block[1]), gunzip_samples(&path, &bytes)?);
            }
        }
    }
    let pool = worker_pool(&bounds, max_zoom.max(cut.anchor), threads)?;
    let available = written.available.clone();
    written.absorb(build_top(
        &samples, &bounds, cut, max_zoom, available, dest, &options, &pool,
    )?);
    write_flat_roots(&mut written, max_zoom, dest, &options, &pool)?;
    let levels = level_reports(&written, &options, max_zoom);
    let finest = levels.last().expect("min_zoom <= max_zoom");
    if finest.tiles == finest.flat_tiles {
        return Err(TerrainError::Options(format!(
            "{}: no tile with a 2x2 block of valid samples at level {max_zoom}, the finest, so \
             there is no terrain to write",
            plan.input
        )));
    }
    for level in levels.iter().rev() {
        progress(level);
    }
    write_layer_json(
        &plan.name,
        dest,
        &options,
        &bounds,
        max_zoom,
        &written.available,
    )?;
    Ok(TerrainReport {
        bounds: bounds_array(&bounds),
        min_zoom: options.min_zoom,
        max_zoom,
        levels,
    })
}
