//! A pyramid built in shards on many machines: each shard builds its blocks into a shared
//! destination and records them (see [`crate::records`]); the merge checks that every
//! shard of one plan is there, builds the levels above the blocks from the blocks' samples,
//! and writes `layer.json` last, so a pyramid appears only when it is complete. The tiles
//! are those of a one-process run, byte for byte (see [`crate::build_terrain`]).

use std::path::Path;

use tinsmith_store::TileStore;

use serde::Serialize;

use crate::base::Stacked;
use crate::blocks::SplitSamples;
use crate::plan::{Plan, Shard, TileOptions};
use crate::pyramid::{
    build_recorded_blocks, finish_pyramid, prepare, worker_pool, Prepared, Progress,
};
use crate::records::{
    block_name, options_key, read_record, read_samples, shard_name, BlockRecord, Entries,
    ShardRecord, RECORDS_DIR,
};
use crate::tms::bounds_array;
use crate::writer::Written;
use crate::{LevelReport, TerrainError, TerrainOptions, TerrainReport, TerrainResult};

/// What [`build_shard`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShardReport {
    /// The shard.
    pub shard: Shard,
    /// Its blocks.
    pub blocks: usize,
    /// Its blocks' weight (valid samples of the plan's coarse read).
    pub weight: u64,
    /// The plan's total weight.
    pub total_weight: u64,
    /// Tiles it wrote.
    pub tiles: u64,
    /// Cells along each side of every tile's lattice ([`crate::lattice_cells`]).
    pub lattice_cells: u32,
    /// Tiles left as an earlier run of the same plan (or input) recorded them: their data
    /// had not changed, so they were not built again.
    pub tiles_kept: u64,
    /// Per level it wrote, coarsest first.
    pub levels: Vec<LevelReport>,
}

/// The recorded tiles of `block` under `dest`, when recorded with options `key`.
fn known_tiles(
    dest: &dyn TileStore,
    split: u8,
    block: [u32; 2],
    key: &str,
) -> TerrainResult<Entries> {
    let name = format!("{}.json", block_name(split, block));
    let record: Option<BlockRecord> = read_record(dest, &name)?;
    Ok(record
        .filter(|r| r.options == key)
        .map(|r| r.tiles.into_iter().map(|t| ((t.z, t.x, t.y), t)).collect())
        .unwrap_or_default())
}

/// Builds shard `shard` of the pyramid of `input` into `dest` (shared by every shard): the tiles of the shard's blocks, their records, then
/// the shard's record. Tiles an earlier run recorded with the same fingerprint (an
/// interrupted run of this shard, or a run over an input since changed elsewhere) are kept
/// as they are. `progress` hears of each block.
///
/// # Errors
/// As [`crate::build_terrain`].
pub fn build_shard(
    input: &Path,
    dest: &dyn TileStore,
    options: &TerrainOptions,
    shard: Shard,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<ShardReport> {
    let start = std::time::Instant::now();
    let Prepared {
        bounds,
        scheme,
        own_level,
        max_zoom,
        fine,
    } = prepare(input, options)?;
    let plan = Plan::new(
        input,
        &bounds,
        own_level,
        TileOptions::new(options, max_zoom, scheme.cells),
        shard.count,
    )?;
    refuse_other_plans(dest, &plan)?;
    let cut = plan.cut();
    let mine = plan.shard_blocks(shard.index);
    let blocks = plan.blocks()[mine.clone()].to_vec();
    let total_weight: u64 = plan.weights.iter().sum();
    progress(Progress::Planned {
        seconds: start.elapsed().as_secs_f64(),
        blocks: plan.weights.len(),
        split: cut.split,
        anchor: cut.anchor,
        shard_blocks: mine.len(),
        share: plan.weights[mine.clone()].iter().sum::<u64>() as f64 / total_weight as f64,
    });
    let pool = worker_pool(
        &bounds,
        cut.tiling,
        max_zoom.max(cut.anchor),
        options.threads,
    )?;
    let source = Stacked::new(input, options)?;
    let key = options_key(options);
    let mut known = Entries::new();
    for block in &blocks {
        let id = [cut.tiling.tile_column(cut.split, block.x0), block.y0];
        known.extend(known_tiles(dest, cut.split, id, &key)?);
    }
    let total = blocks.len();
    let (written, _) = build_recorded_blocks(
        &source,
        &bounds,
        &fine,
        cut,
        max_zoom,
        &blocks,
        dest,
        options,
        &pool,
        &known,
        &mut |done| progress(Progress::Block { done, total }),
    )?;
    let record = ShardRecord {
        plan_id: plan.id(),
        plan: plan.clone(),
        shard,
        blocks: blocks
            .iter()
            .map(|b| [cut.tiling.tile_column(cut.split, b.x0), b.y0])
            .collect(),
    };
    let json = serde_json::to_vec_pretty(&record).expect("a record serializes");
    dest.put_file(&shard_name(shard), &json)?;
    let levels = crate::pyramid::level_reports(&written, cut.tiling, options, max_zoom);
    Ok(ShardReport {
        shard,
        blocks: blocks.len(),
        weight: plan.weights[mine].iter().sum(),
        total_weight: plan.weights.iter().sum(),
        tiles: levels.iter().map(|l| l.tiles).sum(),
        lattice_cells: cut.tiling.cells,
        tiles_kept: written.kept,
        levels,
    })
}

/// The shard records in `dest`, by name, in shard order.
fn shard_records(dest: &dyn TileStore) -> TerrainResult<Vec<(String, ShardRecord)>> {
    let mut out = Vec::new();
    for name in dest.list_files(&format!("{RECORDS_DIR}/shards/"))? {
        if !(name.contains("-of-") && name.ends_with(".json")) {
            continue;
        }
        let record: ShardRecord = read_record(dest, &name)?.expect("listed just now");
        out.push((name, record));
    }
    if out.is_empty() {
        return Err(TerrainError::Options(format!(
            "{}: no shard records ({RECORDS_DIR}/shards/I-of-N.json); run `tinsmith tiles \
             INPUT -o {} --shard I/N` for every I first",
            dest.location(),
            dest.location()
        )));
    }
    out.sort_by_key(|(_, r)| r.shard.index);
    Ok(out)
}

/// Fails, before any tile is written, when `dest` already records a shard of another
/// plan (other options, another shard count, changed data): its tiles would be
/// overwritten by this plan's, leaving neither pyramid whole.
fn refuse_other_plans(dest: &dyn TileStore, plan: &Plan) -> TerrainResult<()> {
    for name in dest.list_files(&format!("{RECORDS_DIR}/shards/"))? {
        if !(name.contains("-of-") && name.ends_with(".json")) {
            continue;
        }
        let Some(record): Option<ShardRecord> = read_record(dest, &name)? else {
            continue;
        };
        if record.plan_id != plan.id() {
            return Err(TerrainError::Options(format!(
                "{}: {name} is a shard of another plan ({}); this run would overwrite its \
                 tiles: write to another destination, or remove that one first",
                dest.location(),
                plan_differences(&record.plan, plan)
            )));
        }
    }
    Ok(())
}

/// What differs between two plans, for a message: the input, the shard count, the
/// input's data, each option that differs.
fn plan_differences(a: &Plan, b: &Plan) -> String {
    let mut differences = Vec::new();
    if a.input != b.input {
        differences.push(format!("input {} vs {}", a.input, b.input));
    }
    if a.shards != b.shards {
        differences.push(format!("{} vs {} shards", a.shards, b.shards));
    }
    if a.fingerprint != b.fingerprint {
        differences.push("the input's data changed between them".to_owned());
    }
    let options = |p: &Plan| serde_json::to_value(&p.options).unwrap_or_default();
    let (oa, ob) = (options(a), options(b));
    if let (Some(oa), Some(ob)) = (oa.as_object(), ob.as_object()) {
        let mut keys: Vec<&String> = oa.keys().chain(ob.keys()).collect();
        keys.sort();
        keys.dedup();
        for key in keys {
            let shown =
                |v: Option<&serde_json::Value>| v.map_or("none".to_owned(), |v| v.to_string());
            if oa.get(key) != ob.get(key) {
                differences.push(format!(
                    "{key} {} vs {}",
                    shown(oa.get(key)),
                    shown(ob.get(key))
                ));
            }
        }
    }
    if differences.is_empty() {
        differences.push("their plans were cut differently".to_owned());
    }
    differences.join(", ")
}

/// Finishes a sharded pyramid in `dest`: checks that every shard of one plan is recorded,
/// builds the levels above the blocks and (with `--metadata`) the flat roots, and writes
/// `layer.json` last. Refuses, naming them, shards of different plans, missing shards, or
/// block records that do not match; then no `layer.json` is written.
pub fn merge_shards(
    dest: &dyn TileStore,
    threads: usize,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<TerrainReport> {
    let records = shard_records(dest)?;
    let (first_path, first) = &records[0];
    for (path, record) in &records {
        if record.plan_id != first.plan_id || record.plan_id != record.plan.id() {
            return Err(TerrainError::Options(format!(
                "{} and {} in {} belong to different plans ({}): keep the shards of one run \
                 only",
                first_path,
                path,
                dest.location(),
                plan_differences(&first.plan, &record.plan)
            )));
        }
    }
    let plan = &first.plan;
    let missing: Vec<Shard> = (0..plan.shards)
        .filter(|i| !records.iter().any(|(_, r)| r.shard.index == *i))
        .map(|index| Shard {
            index,
            count: plan.shards,
        })
        .collect();
    if !missing.is_empty() {
        return Err(TerrainError::Options(format!(
            "{}: shard{} {} of the plan missing (no {}); no layer.json written",
            dest.location(),
            if missing.len() > 1 { "s" } else { "" },
            missing
                .iter()
                .map(Shard::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            missing
                .iter()
                .map(|&s| shard_name(s))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let options = plan.options.to_options(threads);
    let key = options_key(&options);
    let bounds = plan.bounds();
    let cut = plan.cut();
    let max_zoom = plan.options.max_zoom;
    let mut written = Written::default();
    let mut samples = SplitSamples::default();
    for (path, record) in &records {
        let expected: Vec<[u32; 2]> = plan.blocks()[plan.shard_blocks(record.shard.index)]
            .iter()
            .map(|b| [cut.tiling.tile_column(cut.split, b.x0), b.y0])
            .collect();
        if record.blocks != expected {
            return Err(TerrainError::Options(format!(
                "{}/{}: its blocks are not those its plan gives shard {}",
                dest.location(),
                path,
                record.shard
            )));
        }
        for &block in &record.blocks {
            let name = block_name(cut.split, block);
            let done: Option<BlockRecord> = read_record(dest, &format!("{name}.json"))?;
            let Some(done) = done.filter(|d| d.options == key) else {
                return Err(TerrainError::Options(format!(
                    "{}: block record {name}.json is missing or of other options; re-run \
                     shard {}",
                    dest.location(),
                    record.shard
                )));
            };
            let mut one = Written::default();
            one.reports.resize(usize::from(max_zoom) + 1, None);
            one.available
                .resize(usize::from(max_zoom) + 1, Default::default());
            for tile in &done.tiles {
                if tile.written {
                    one.available[usize::from(tile.z)].insert((tile.x, tile.y));
                    if let Some(bounds) = tile.bounds {
                        one.metadata.insert((tile.z, tile.x, tile.y), bounds);
                    }
                }
                let (tiling, quality) = (cut.tiling, options.quality);
                let report = one.reports[usize::from(tile.z)]
                    .get_or_insert_with(|| LevelReport::empty(tiling, tile.z, quality));
                crate::records::count(report, tile);
            }
            written.absorb(one);
            if done.samples {
                let values = read_samples(dest, &format!("{name}.samples"), cut.tiling.cells)?;
                samples.tiles.insert((block[0], block[1]), values);
            }
        }
    }
    let known: Entries =
        read_record::<crate::records::TopRecord>(dest, &crate::records::top_name())?
            .filter(|r| r.options == key)
            .map(|r| r.tiles.into_iter().map(|t| ((t.z, t.x, t.y), t)).collect())
            .unwrap_or_default();
    let pool = worker_pool(&bounds, cut.tiling, max_zoom.max(cut.anchor), threads)?;
    let (levels, tiles_kept) = finish_pyramid(
        &plan.name, written, &samples, &bounds, cut, max_zoom, dest, &options, &pool, &known,
        progress,
    )
    .map_err(|e| match e {
        TerrainError::NoTerrain { level } => TerrainError::Options(format!(
            "{}: no tile with a 2x2 block of valid samples at level {level}, the finest, so \
             there is no terrain to write",
            plan.input
        )),
        other => other,
    })?;
    Ok(TerrainReport {
        bounds: bounds_array(&bounds),
        min_zoom: options.min_zoom,
        max_zoom,
        lattice_cells: cut.tiling.cells,
        levels,
        tiles_kept,
    })
}
