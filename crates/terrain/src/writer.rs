//! The stream's sink that builds, checks and writes tiles: for one block (the tiles under
//! one tile of the split level) or for the levels above the blocks.

use std::collections::BTreeSet;
use std::ops::{Range, RangeInclusive};
use std::time::Instant;

use rayon::prelude::*;
use sha2::Digest;
use tinsmith_store::{TileEncoding, TileStore};

use crate::budget::LevelBudget;
use crate::implicit::{tile_path, TileMetadata};
use crate::layer::{metadata_json, Available};
use crate::records::{count, options_key, tile_sum, Entries, TileEntry};
use crate::rows::LevelRows;
use crate::stream::LevelSink;
use crate::tile::{build_tile, TileOut};
use crate::tms::{Scheme, TileRect};
use crate::{
    LevelReport, TerrainError, TerrainOptions, TerrainResult, TileFormat, METADATA_AVAILABILITY,
};

/// Which tiles a writer writes.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scope {
    /// Levels written.
    pub(super) levels: (u8, u8),
    /// Only the tiles under this tile (a block), or every tile of the levels.
    pub(super) under: Option<TileRect>,
    /// The tiling and tile lattice.
    pub(super) scheme: Scheme,
}

impl Scope {
    fn levels(&self) -> RangeInclusive<u8> {
        self.levels.0..=self.levels.1
    }

    /// Whether tile `x`, `y` of level `z` (any turn) is written.
    fn writes(&self, z: u8, x: u32, y: u32) -> bool {
        if !self.levels().contains(&z) {
            return false;
        }
        match self.under {
            None => true,
            Some(block) if z >= block.level => {
                let f = z - block.level;
                let below = TileRect {
                    tiling: block.tiling,
                    level: z,
                    x0: block.x0 << f,
                    y0: block.y0 << f,
                    width: block.width << f,
                    height: block.height << f,
                };
                below.contains(x, y)
            }
            Some(_) => false,
        }
    }
}

/// What a writer produced.
#[derive(Debug, Default)]
pub(super) struct Written {
    /// Per level 0..=max_zoom (levels not written stay empty).
    pub(super) reports: Vec<Option<LevelReport>>,
    /// Tiles written, per level.
    pub(super) available: Available,
    /// Every tile considered, as its record keeps it.
    pub(super) entries: Vec<TileEntry>,
    /// Of them, tiles whose data had not changed since the run that recorded them: left
    /// as they were, not built again.
    pub(super) kept: u64,
    /// 3D Tiles: each tile written's metadata, for the subtrees.
    pub(super) metadata: TileMetadata,
}

impl Written {
    /// Adds `other`'s tiles and counts to these.
    pub(super) fn absorb(&mut self, other: Written) {
        if self.reports.len() < other.reports.len() {
            self.reports.resize(other.reports.len(), None);
            self.available
                .resize(other.available.len(), BTreeSet::new());
        }
        for (mine, theirs) in self.reports.iter_mut().zip(other.reports) {
            match (mine.as_mut(), theirs) {
                (_, None) => {}
                (None, Some(t)) => *mine = Some(t),
                (Some(m), Some(t)) => m.absorb(&t),
            }
        }
        for (mine, theirs) in self.available.iter_mut().zip(other.available) {
            mine.extend(theirs);
        }
        self.entries.extend(other.entries);
        self.kept += other.kept;
        self.metadata.extend(other.metadata);
    }
}

/// The sink: builds the tiles of `scope` from each level's rows, stores them in
/// `store`, and, for a block, keeps the block tile's samples (what the levels above are
/// filtered from).
pub(super) struct TileWriter<'a> {
    scope: Scope,
    /// [`options_key`] of the run.
    key: String,
    /// Tiles a previous run recorded, by address.
    known: &'a Entries,
    store: &'a dyn TileStore,
    options: &'a TerrainOptions,
    pool: &'a rayon::ThreadPool,
    budgets: Vec<LevelBudget>,
    written: Written,
    /// The samples of the block's own tile at its level, once seen.
    pub(super) block_samples: Option<Vec<f32>>,
}

impl<'a> TileWriter<'a> {
    /// A writer for `scope`, up to level `max_zoom`, that knows the tiles in `available`
    /// already (levels below the scope, for the metadata extension).
    pub(super) fn new(
        scope: Scope,
        max_zoom: u8,
        available: Available,
        known: &'a Entries,
        store: &'a dyn TileStore,
        options: &'a TerrainOptions,
        pool: &'a rayon::ThreadPool,
    ) -> Self {
        let levels = usize::from(max_zoom) + 1;
        let mut available = available;
        available.resize(levels, BTreeSet::new());
        TileWriter {
            scope,
            key: options_key(options),
            known,
            store,
            options,
            pool,
            budgets: (0..=max_zoom)
                .map(|z| LevelBudget::new(scope.scheme, z, options.quality))
                .collect(),
            written: Written {
                reports: vec![None; levels],
                available,
                entries: Vec::new(),
                kept: 0,
                metadata: TileMetadata::new(),
            },
            block_samples: None,
        }
    }

    /// What was written.
    pub(super) fn finish(self) -> Written {
        self.written
    }

    /// The report of level `z`, started when first needed.
    fn report(&mut self, z: u8) -> &mut LevelReport {
        let (tiling, quality) = (self.scope.scheme, self.options.quality);
        self.written.reports[usize::from(z)]
            .get_or_insert_with(|| LevelReport::empty(tiling, z, quality))
    }

    /// Builds root tile `x` flat (the raster does not reach it) and writes it, unless the
    /// same is recorded as written already.
    pub(super) fn write_flat_root(&mut self, x: u32) -> TerrainResult<()> {
        let available = self.options.metadata.then_some(&self.written.available);
        let metadata = available.map(|a| metadata_json(a, 0, x, 0));
        let cells = self.scope.scheme.cells;
        let sum = tile_sum(&self.key, (0, x, 0), metadata.as_deref(), |h| {
            h.update(b"flat");
            // The lattice shapes a flat tile (its edge cap, its `u` steps); absent for the
            // default, so that earlier pyramids keep their sums.
            if cells != crate::tms::LATTICE_CELLS[0] {
                h.update(cells.to_le_bytes());
            }
        });
        let outcome = match self.known.get(&(0, x, 0)) {
            Some(entry) if entry.sum == sum && keepable(entry, self.options.format) => {
                Outcome::Kept(entry.clone())
            }
            _ => {
                let flat = LevelRows::flat_tile(self.scope.scheme, 0, x, 0);
                let tile = build_tile(&flat, x, 0, &self.budgets[0], self.options, available)?;
                Outcome::Built(0, x, 0, sum, tile)
            }
        };
        self.apply(outcome)?;
        self.report(0).flat_tiles += 1;
        Ok(())
    }

    /// Records a tile kept or built (writing it, or removing one a previous run wrote
    /// where there is none now).
    fn apply(&mut self, outcome: Outcome) -> TerrainResult<()> {
        let entry = match outcome {
            Outcome::Kept(entry) => {
                self.written.kept += 1;
                if let (true, Some(bounds)) = (entry.written, entry.bounds) {
                    self.written
                        .metadata
                        .insert((entry.z, entry.x, entry.y), bounds);
                }
                entry
            }
            Outcome::Built(z, x, y, sum, tile) => {
                let entry = match &tile {
                    Some(t) => TileEntry {
                        z,
                        x,
                        y,
                        sum,
                        written: true,
                        bytes: t.bytes.len() as u64,
                        vertices: t.vertices as u64,
                        triangles: t.triangles as u64,
                        max_error: t.max_error,
                        verified_bound: t.verified_bound,
                        bounds: t.bounds,
                    },
                    None => TileEntry {
                        z,
                        x,
                        y,
                        sum,
                        written: false,
                        bytes: 0,
                        vertices: 0,
                        triangles: 0,
                        max_error: 0.0,
                        verified_bound: 0.0,
                        bounds: None,
                    },
                };
                if let Some(bounds) = tile.as_ref().and_then(|t| t.bounds) {
                    self.written.metadata.insert((z, x, y), bounds);
                }
                match tile {
                    Some(t) => self.write(z, &t)?,
                    None if self.known.get(&(z, x, y)).is_some_and(|e| e.written) => {
                        self.remove(z, x, y)?
                    }
                    None => {}
                }
                entry
            }
        };
        if entry.written {
            self.written.available[usize::from(entry.z)].insert((entry.x, entry.y));
        }
        count(self.report(entry.z), &entry);
        self.written.entries.push(entry);
        Ok(())
    }

    /// Removes tile `z/x/y` (no longer any data there).
    fn remove(&self, z: u8, x: u32, y: u32) -> TerrainResult<()> {
        remove_tile(self.store, self.options.format, (z, x, y))
    }

    /// Stores a tile of level `z`.
    fn write(&mut self, z: u8, tile: &TileOut) -> TerrainResult<()> {
        if tinsmith_output::interrupted() {
            // The run is being torn down: add nothing.
            return Err(TerrainError::Output {
                path: self.store.location().into(),
                source: std::io::Error::from(std::io::ErrorKind::Interrupted),
            });
        }
        if self.options.format == TileFormat::ThreeDTiles {
            return Ok(self
                .store
                .put_file(&tile_path(z, tile.x, tile.y), &tile.bytes)?);
        }
        let encoding = if self.options.gzip {
            TileEncoding::Gzip
        } else {
            TileEncoding::Identity
        };
        Ok(self
            .store
            .put_tile(z, tile.x, tile.y, &tile.bytes, encoding)?)
    }
}

/// Whether a recorded tile with the fingerprint of this run's may be kept as it is: a 3D
/// Tiles tile needs its subtree metadata recorded too (records written before it was are
/// rebuilt, so that the subtrees are whole).
fn keepable(entry: &TileEntry, format: TileFormat) -> bool {
    format != TileFormat::ThreeDTiles || !entry.written || entry.bounds.is_some()
}

/// Removes tile `z/x/y` of a pyramid of `format` from `store`.
pub(super) fn remove_tile(
    store: &dyn TileStore,
    format: TileFormat,
    (z, x, y): (u8, u32, u32),
) -> TerrainResult<()> {
    match format {
        TileFormat::QuantizedMesh => Ok(store.delete_tile(z, x, y)?),
        TileFormat::ThreeDTiles => Ok(store.delete_file(&tile_path(z, x, y))?),
    }
}

/// A tile's fate in a run.
enum Outcome {
    /// Its data has not changed since it was recorded: left as it is.
    Kept(TileEntry),
    /// Built (level, column, row, fingerprint; `None`: no valid cell).
    Built(u8, u32, u32, String, Option<TileOut>),
}

/// The tiles of tile rows `tile_rows` (local) of a level, in TMS row then column order.
fn tiles_of(level: &LevelRows, tile_rows: Range<u32>) -> Vec<(u32, u32)> {
    tile_rows
        .flat_map(|j| (0..level.tiles_x).map(move |i| (level.tx0 + i, level.ty0 + j)))
        .collect()
}

impl LevelSink for TileWriter<'_> {
    fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()> {
        let z = level.level;
        let t = Instant::now();
        let mut tiles = tiles_of(level, tile_rows);
        if let Some(block) = self.scope.under.filter(|b| b.level == z) {
            if let Some(&(x, y)) = tiles.iter().find(|&&(x, y)| block.contains(x, y)) {
                let values = level.tile_values(x, y);
                self.block_samples = Some(values.iter().map(|&v| v as f32).collect());
            }
        }
        tiles.retain(|&(x, y)| self.scope.writes(z, x, y));
        if tiles.is_empty() {
            return Ok(());
        }
        let budget = &self.budgets[usize::from(z)];
        let (options, key, known) = (self.options, self.key.as_str(), self.known);
        // Finer levels inside these tiles' footprints are complete (see `stream_levels`).
        let metadata_available = if options.metadata && z.is_multiple_of(METADATA_AVAILABILITY) {
            Some(&self.written.available)
        } else {
            None
        };
        let outcomes: Vec<TerrainResult<Outcome>> = self.pool.install(|| {
            tiles
                .par_iter()
                .map(|&(x, y)| {
                    let column = level.tiling.tile_column(z, x);
                    let metadata = metadata_available.map(|a| metadata_json(a, z, column, y));
                    let sum = tile_sum(key, (z, column, y), metadata.as_deref(), |h| {
                        level.hash_tile_window(x, y, h)
                    });
                    match known.get(&(z, column, y)) {
                        Some(entry) if entry.sum == sum && keepable(entry, options.format) => {
                            Ok(Outcome::Kept(entry.clone()))
                        }
                        _ => {
                            let tile =
                                build_tile(level, x, y, budget, options, metadata_available)?;
                            Ok(Outcome::Built(z, column, y, sum, tile))
                        }
                    }
                })
                .collect()
        });
        for outcome in outcomes {
            self.apply(outcome?)?;
        }
        self.report(z).seconds += t.elapsed().as_secs_f64();
        Ok(())
    }

    fn level_done(&mut self, level: u8, seconds: f64) -> TerrainResult<()> {
        if self.scope.levels().contains(&level) {
            self.report(level).seconds += seconds;
        }
        Ok(())
    }
}
