//! A Cesium quantized-mesh terrain pyramid: geographic TMS tiles (EPSG:4326, 2x1 root
//! tiles, y = 0 in the south) or Web Mercator ones (EPSG:3857, 1x1, see [`Tiling`]), each
//! decimated within `quality x e(level)`, with shared edges simplified once so that
//! same-level neighbours keep identical edge vertices.

use std::path::Path;

use tinsmith_output::StagedDir;
use tinsmith_raster::{geographic_bounds, GeoBounds};

use crate::base::Stacked;
use crate::blocks::{block_level, block_window, blocks, domain, reach_margin, Cut, SplitSamples};
use crate::budget::LevelBudget;
use crate::implicit::{subtree_levels, subtrees, tileset_json};
use crate::layer::{layer_json, Available};
use crate::records::{
    block_name, gzip_samples, options_key, put_record, read_record, top_name, BlockRecord, Entries,
    TopRecord, RECORDS_DIR,
};
use crate::rows::LevelRows;
use crate::stream::{band_tile_rows, stream_levels, RowSource};
use crate::tms::{bounds_array, lattice_cells, own_level, Scheme, TileRect, Tiling};
use crate::writer::{remove_tile, Scope, TileWriter, Written};
use crate::{TerrainError, TerrainResult};
use tinsmith_store::{DirectoryStore, TileStore};

/// The largest `--quality`: the level-0 bound is then 7.7e10 m, beyond any height; larger
/// values only risk overflowing the bounds.
const MAX_QUALITY: f64 = 1e6;

/// The finest level [`build_terrain`] will go to.
pub const MAX_LEVEL: u8 = 24;

/// Options of [`build_terrain`].
#[derive(Debug, Clone, PartialEq)]
pub struct TerrainOptions {
    /// 1-based band.
    pub band: usize,
    /// Coarsest level written.
    pub min_zoom: u8,
    /// Finest level; `None`: the first level whose tile sample spacing is at most the
    /// input's resolution.
    pub max_zoom: Option<u8>,
    /// Each tile's bound is `quality x e(level)` metres.
    pub quality: f64,
    /// Add oct-encoded vertex normals (extension 1).
    pub normals: bool,
    /// Add the metadata extension (4) at levels 0, 10, 20 and `metadataAvailability`.
    pub metadata: bool,
    /// Gzip each tile.
    pub gzip: bool,
    /// Worker threads (0: rayon's default).
    pub threads: usize,
    /// Bytes the run may use; a level range whose streaming would need more (see
    /// [`streaming_bytes`]) is refused before any work. `None`: no limit.
    pub memory_limit: Option<u64>,
    /// Update the pyramid in `out_dir` in place: rebuild only the tiles whose data (or
    /// metadata) changed since its records, remove those that no longer have data.
    pub update: bool,
    /// What the band's heights are measured from: each sample `H` is written as the
    /// ellipsoidal height `H + N` (the geoid's height `N` from PROJ), which is what
    /// CesiumJS draws. Part of every tile's identity (a change rebuilds every tile).
    pub vertical_datum: tinsmith_raster::VerticalDatum,
    /// Add the water mask extension (2) from this source.
    pub water: Option<crate::Water>,
    /// Draw the whole globe: the globe beyond the raster (and the base) is flat at height
    /// 0 on the ellipsoid, whatever `vertical_datum` (not on the geoid, which is up to
    /// about 100 m from it), every tile the raster reaches covers its whole rectangle, and
    /// both root tiles are written, so that a client shows a globe with the data on it.
    /// Without it, tiles have no triangles beyond the raster.
    pub whole_globe: bool,
    /// How tiles are encoded and laid out. Part of every tile's identity.
    pub format: TileFormat,
    /// How tiles divide the globe. A Web Mercator pyramid tiles the part of the raster
    /// within its latitudes (about ±85.0511°).
    pub tiling: Tiling,
    /// A raster under the input: its heights wherever the input has no valid sample, and
    /// its extent added to the pyramid's down to the base's own level; the levels finer
    /// than that cover the input's extent only. Part of every tile's identity.
    pub base: Option<crate::BaseRaster>,
}

/// How a pyramid's tiles are encoded and laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum TileFormat {
    /// quantized-mesh-1.0 tiles `z/x/y.terrain` and `layer.json`, for CesiumJS's
    /// `CesiumTerrainProvider`.
    #[default]
    #[serde(rename = "quantized-mesh")]
    QuantizedMesh,
    /// 3D Tiles 1.1 terrain for CesiumJS's `Cesium3DTilesTerrainProvider`: one GLB per
    /// tile with `CESIUM_tile_edges` under `tiles/`, implicit quadtree subtrees with each
    /// tile's metadata under `subtrees/`, and `tileset.json`. Always the whole globe,
    /// from level 0, into a directory or a bucket; GLBs are not gzipped.
    #[serde(rename = "3dtiles")]
    ThreeDTiles,
}

impl TileFormat {
    /// The name the command line gives it: `quantized-mesh` or `3dtiles`.
    pub fn label(self) -> &'static str {
        match self {
            TileFormat::QuantizedMesh => "quantized-mesh",
            TileFormat::ThreeDTiles => "3dtiles",
        }
    }
}

impl TerrainOptions {
    /// The height of the globe beyond the raster: 0 for [`TerrainOptions::whole_globe`],
    /// else NaN (no data).
    pub(super) fn outside(&self) -> f32 {
        if self.whole_globe {
            0.0
        } else {
            f32::NAN
        }
    }
}

impl Default for TerrainOptions {
    fn default() -> Self {
        TerrainOptions {
            band: 1,
            min_zoom: 0,
            max_zoom: None,
            quality: 1.0,
            normals: false,
            metadata: false,
            gzip: true,
            threads: 0,
            memory_limit: None,
            update: false,
            vertical_datum: tinsmith_raster::VerticalDatum::Ellipsoid,
            water: None,
            whole_globe: false,
            format: TileFormat::QuantizedMesh,
            tiling: Tiling::Geographic,
            base: None,
        }
    }
}

/// The tiling and tile lattice of a pyramid whose own level is that of a raster over
/// `bounds` ([`lattice_cells`]), and that level: the first whose lattice is at least as
/// fine as the raster (in longitude; a Web Mercator tile's rows are closer).
fn own_scheme(bounds: &GeoBounds, tiling: Tiling) -> (Scheme, u8) {
    let cells = lattice_cells(bounds.resolution, tiling);
    (
        Scheme { tiling, cells },
        own_level(bounds.resolution, tiling, cells),
    )
}

/// About how many bytes building a pyramid over `bounds` down to `max_zoom` takes: the
/// bands of whole tile rows of a block's window at the finest level streamed (one per
/// thread in the warp, a few held), 4 bytes a sample, with the coarser levels' rows (a
/// third more); the rows of the levels above the blocks; every block's samples at the
/// split level; and the record of every tile written (for `layer.json`'s availability,
/// about 48 bytes a tile). An estimate for refusing hopeless runs (a small raster at a far
/// finer level than its own, a raster too wide), not a bound.
pub fn streaming_bytes(bounds: &GeoBounds, tiling: Tiling, max_zoom: u8, threads: usize) -> u64 {
    let (scheme, own_level) = own_scheme(bounds, tiling);
    streaming_bytes_of(bounds, scheme, own_level, max_zoom, threads)
}

/// [`streaming_bytes`] of a pyramid of `scheme` whose own level is `own_level`.
fn streaming_bytes_of(
    bounds: &GeoBounds,
    tiling: Scheme,
    own_level: u8,
    max_zoom: u8,
    threads: usize,
) -> u64 {
    let cut = Cut::coarsest(tiling, own_level);
    let finest = max_zoom.max(cut.anchor);
    let cells = u64::from(tiling.cells + 1);
    let bands = threads.max(1) as u64 + 3;
    let band_bytes = |tiles_wide: u64| {
        (tiles_wide.saturating_mul(u64::from(tiling.cells)) * cells)
            .max(1 << 22)
            .saturating_mul(bands)
            .saturating_mul(4)
    };
    let domain = |level: u8| domain(bounds, tiling, level);
    let domain_wide = u64::from(domain(finest).width);
    let window_wide = domain_wide.min((1u64 << (finest - cut.split).min(40)) + 2);
    let blocks = band_bytes(window_wide);
    let top = band_bytes(u64::from(domain(cut.split).width));
    let split_samples = domain(cut.split).tiles().saturating_mul(cells * cells * 4);
    let records = domain(finest).tiles().saturating_mul(48);
    blocks
        .max(top)
        .saturating_add(split_samples)
        .saturating_add(records)
        .saturating_mul(4)
        / 3
}

/// Levels finer than the raster's own resolution a pyramid may go before its tile count
/// is limited by [`OVERZOOM_TILES`]: beyond, tiles only interpolate between samples.
const OVERZOOM_LEVELS: u8 = 4;

/// The most tiles a level more than [`OVERZOOM_LEVELS`] finer than the raster's own
/// resolution may have.
const OVERZOOM_TILES: u64 = 1_000_000;

/// What one level produced.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LevelReport {
    /// The level.
    pub level: u8,
    /// The bound asked for, `quality x e(level)` (m).
    pub bound: f64,
    /// The bound achieved: the bound, or half the height quantum when that is larger
    /// (the 16-bit heights cannot do better).
    pub achieved_bound: f64,
    /// The height quantum of the level (m): every tile's heights are multiples of it.
    pub height_step: f64,
    /// The largest error measured over all tiles (m), decoded heights against the tile
    /// grids' samples.
    pub measured_max_error: f64,
    /// Tiles written.
    pub tiles: u64,
    /// Tiles with data in range but no valid cell, not written.
    pub empty_tiles: u64,
    /// Of `tiles`, at level 0 with `--metadata` only: root tiles the raster does not
    /// reach, written flat at height 0 (the ellipsoid), since CesiumJS then takes both
    /// roots to exist.
    pub flat_tiles: u64,
    /// Bytes written (as stored, gzipped or not).
    pub bytes: u64,
    /// Vertices over all tiles.
    pub vertices: u64,
    /// Triangles over all tiles.
    pub triangles: u64,
    /// Seconds spent on the level, summed over both passes: making its rows (the warp
    /// for the finest level, the downsampling for the others), its statistics and its
    /// tiles. Levels interleave in time, so the levels' seconds add up to about the wall
    /// time.
    pub seconds: f64,
}

impl LevelReport {
    /// The report of a level with no tile yet.
    pub(crate) fn empty(tiling: Scheme, level: u8, quality: f64) -> LevelReport {
        let budget = LevelBudget::new(tiling, level, quality);
        LevelReport {
            level,
            bound: budget.bound,
            achieved_bound: budget.bound,
            height_step: budget.step,
            measured_max_error: 0.0,
            tiles: 0,
            empty_tiles: 0,
            flat_tiles: 0,
            bytes: 0,
            vertices: 0,
            triangles: 0,
            seconds: 0.0,
        }
    }

    /// Adds `other`'s tiles and counts (the same level, another part of it) to these.
    pub(crate) fn absorb(&mut self, other: &LevelReport) {
        self.achieved_bound = self.achieved_bound.max(other.achieved_bound);
        self.measured_max_error = self.measured_max_error.max(other.measured_max_error);
        self.tiles += other.tiles;
        self.empty_tiles += other.empty_tiles;
        self.flat_tiles += other.flat_tiles;
        self.bytes += other.bytes;
        self.vertices += other.vertices;
        self.triangles += other.triangles;
        self.seconds += other.seconds;
    }
}

/// What [`build_terrain`] produced.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TerrainReport {
    /// The input's extent in EPSG:4326, `[west, south, east, north]`: west > east across
    /// the antimeridian; Web Mercator tiles' only up to their ±85.0511° latitude.
    pub bounds: [f64; 4],
    /// Coarsest level.
    pub min_zoom: u8,
    /// Finest level.
    pub max_zoom: u8,
    /// Cells along each side of every tile's lattice ([`crate::lattice_cells`]): a tile
    /// samples `(cells + 1)^2` points, vertex `u` (and `v`) of lattice column `i` is
    /// `i x 32767 / cells`.
    pub lattice_cells: u32,
    /// Per level, coarsest first.
    pub levels: Vec<LevelReport>,
    /// Tiles left as a previous build recorded them (`--update`, or a shard run again):
    /// their data had not changed, so they were not built again.
    pub tiles_kept: u64,
}

/// Builds the pyramid of `input` into `out_dir`: `z/x/y.terrain` tiles and `layer.json`.
///
/// # Guarantees
/// - **A tile is a function of its own data.** The bytes of tile z/x/y depend only on the
///   input, z/x/y and the options that shape tiles (band, quality, normals, metadata,
///   gzip, tiling...): not on `--min-zoom`, `--max-zoom` (except the metadata extension of levels
///   0, 10 and 20, which lists the tiles below down to `--max-zoom`), the threads, or
///   which other tiles a run (or a shard of one, [`crate::build_shard`]) builds. Level L's
///   lattice is defined once: the raster's own level is sampled from the raster (bilinear,
///   each sample from its position alone), each coarser level is the finer one filtered
///   (binomial 5 x 5) and halved (Web Mercator: filtered from the finer rows resampled
///   in latitude, see [`Tiling::Mercator`]), and each finer level is sampled alone.
///   With [`TerrainOptions::base`], each lattice point is the input's sample where valid,
///   else the base's; the base's own level is the anchor, over both rasters' extent, and
///   the finer levels cover the input's extent only.
/// - **Bound.** At every valid sample of a tile's grid (its `(cells + 1)^2` lattice
///   points of its level), the decoded tile (float32 min/max, 16-bit heights) is within
///   `quality x e(level)` of the sample, or within half the level's height quantum and
///   a rounding margin when that is larger (reported as `achieved_bound`); checked for
///   every tile by `tinsmith-verify` before the tile is written.
/// - **Stitching.** Same-level neighbours have the same vertices along their shared edge,
///   at the same positions, with heights on the level's common lattice (multiples of
///   `height_step`, fixed by the level's bound), so they decode to the same heights.
/// - Tiles without a valid cell are not written and not listed in `available`.
/// - **Memory.** The pyramid is built block by block (a tile of the split level, at most
///   four levels above the raster's own, and the tiles under it, from a window of the
///   raster with a ring of one tile), a few bands of each block's tile rows at a time;
///   then the levels above the blocks from the blocks' samples at the split level.
/// - All or nothing: the pyramid is staged beside `out_dir` and renamed into place.
pub fn build_terrain(
    input: &Path,
    out_dir: &Path,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<TerrainReport> {
    let prepared = prepare(input, options)?;
    // All or nothing: the pyramid is built in a temporary directory beside `out_dir` and
    // renamed into place at the end; a failure (or nothing to write) leaves no trace. An
    // update works in place, tile by tile.
    let staging = if options.update {
        None
    } else {
        Some(stage_pyramid(out_dir)?)
    };
    let store = DirectoryStore::open(staging.as_ref().map_or(out_dir, |s| s.path()))?;
    let known = if options.update {
        recorded_entries(&store)?
    } else {
        Entries::new()
    };
    let report = build_into(input, prepared, &store, &known, options, progress)?;
    if let Some(staging) = staging {
        staging.commit().map_err(|source| TerrainError::Output {
            path: out_dir.to_path_buf(),
            source,
        })?;
    }
    Ok(report)
}

/// Builds the pyramid of `input` into `store` (an object store, a container) directly:
/// tiles and their records first, `layer.json` last, so that the pyramid appears only when
/// it is complete. Tiles the store's records already hold with the same fingerprint (a
/// run interrupted, or an input changed elsewhere) are kept as they are, and tiles that no
/// longer have data are removed; so a re-run after a failure completes the pyramid, and
/// `update` is implied.
///
/// # Guarantees
/// As [`build_terrain`], except all-or-nothing: a failed run leaves the tiles it wrote
/// (and any `layer.json` of an earlier complete run, untouched until the end).
pub fn build_terrain_in(
    input: &Path,
    store: &dyn TileStore,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<TerrainReport> {
    let prepared = prepare(input, options)?;
    let known = if store.get_file(&top_name())?.is_some() {
        recorded_entries(store)?
    } else {
        Entries::new()
    };
    build_into(input, prepared, store, &known, options, progress)
}

/// The pyramid of `input` into `store`, keeping the tiles `known` with the same
/// fingerprint, removing those that no longer have data and the records of blocks no
/// longer in the run.
fn build_into(
    input: &Path,
    prepared: Prepared,
    store: &dyn TileStore,
    known: &Entries,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<TerrainReport> {
    let Prepared {
        bounds,
        scheme,
        own_level,
        max_zoom,
        fine,
    } = prepared;
    let source = Stacked::new(input, options)?;
    let cut = Cut::coarsest(scheme, own_level);
    let pool = worker_pool(
        &bounds,
        cut.tiling,
        max_zoom.max(cut.anchor),
        options.threads,
    )?;
    let all = blocks(&bounds, cut);
    let total = all.len();
    let (written, samples) = build_recorded_blocks(
        &source,
        &bounds,
        &fine,
        cut,
        max_zoom,
        &all,
        store,
        options,
        &pool,
        known,
        &mut |done| progress(Progress::Block { done, total }),
    )?;
    let (levels, tiles_kept) = finish_pyramid(
        &layer_name(input),
        written,
        &samples,
        &bounds,
        cut,
        max_zoom,
        store,
        options,
        &pool,
        known,
        progress,
    )
    .map_err(|e| match e {
        TerrainError::NoTerrain { level } => no_terrain(input, options, level),
        other => other,
    })?;
    if !known.is_empty() {
        remove_stale_records(store, cut, &all)?;
    }
    Ok(TerrainReport {
        bounds: bounds_array(&bounds),
        min_zoom: options.min_zoom,
        max_zoom,
        lattice_cells: cut.tiling.cells,
        levels,
        tiles_kept,
    })
}

/// The refusal of a pyramid whose finest level has no tile with data.
fn no_terrain(input: &Path, options: &TerrainOptions, level: u8) -> TerrainError {
    // The coarser levels are made from the finest, each reaching a sample further out
    // (see `LevelRows::coarser_rows`): without a triangle at the finest level they would
    // only smear samples that hold none (a single valid sample, a single row) into
    // terrain, where `mesh` and `contour` find nothing to triangulate.
    let hint = if options.max_zoom.is_some() {
        " (at this --max-zoom the tile samples may be too far apart for the raster's \
         extent: try a larger one)"
    } else {
        ""
    };
    TerrainError::Options(format!(
        "{}: band {} has no tile with a 2x2 block of valid samples at level {level}, the \
         finest (the coarser levels are made from it), so there is no terrain to write{hint}",
        input.display(),
        options.band,
    ))
}

/// What a long build reports as it goes.
#[derive(Debug, Clone, Copy)]
pub enum Progress<'a> {
    /// `done` of `total` blocks are built.
    Block {
        /// Blocks finished.
        done: usize,
        /// Blocks in the run.
        total: usize,
    },
    /// A level is finished (all of them at the end, finest first).
    Level(&'a LevelReport),
    /// A shard's plan is made.
    Planned {
        /// Seconds the plan took (the input's checks, fingerprint and coarse read).
        seconds: f64,
        /// Blocks in the plan.
        blocks: usize,
        /// Their level.
        split: u8,
        /// The raster's own level.
        anchor: u8,
        /// Of them, this shard's.
        shard_blocks: usize,
        /// This shard's share of the plan's weight, 0 to 1.
        share: f64,
    },
}

/// What every run of a pyramid works out from its input and options first.
pub(super) struct Prepared {
    /// The pyramid's extent in EPSG:4326: the input's, with a base the base's too.
    pub(super) bounds: GeoBounds,
    /// The tiling and the tile lattice: the one that fits the anchor's raster best
    /// ([`lattice_cells`]).
    pub(super) scheme: Scheme,
    /// The raster's own level (the anchor); with a base, the base's.
    pub(super) own_level: u8,
    /// The finest level written.
    pub(super) max_zoom: u8,
    /// The extent of the levels finer than the anchor: the input's.
    pub(super) fine: GeoBounds,
}

/// Checks `options` against `input` and works out its bounds and levels; refuses, saying
/// why, options that make no sense and runs that could not finish (too many tiles, too
/// much memory, heights beyond float32).
pub(super) fn prepare(input: &Path, options: &TerrainOptions) -> TerrainResult<Prepared> {
    crate::base::refuse_clashes(options)?;
    if !(options.quality > 0.0 && options.quality <= MAX_QUALITY) {
        return Err(TerrainError::Options(format!(
            "--quality must be a positive number up to {MAX_QUALITY:e}, got {:?}",
            options.quality
        )));
    }
    let mut bounds = geographic_bounds(input, options.band)?;
    if bounds.south >= bounds.north {
        return Err(TerrainError::Options(
            "the raster lies outside latitudes -90..90 in EPSG:4326: no tile can hold it \
             (is its georeferencing right?)"
                .into(),
        ));
    }
    // Web Mercator tiles end short of the poles: the part of the raster beyond is left
    // out, and a raster wholly beyond is refused.
    clip_to_tiling(&mut bounds, options.tiling, |beyond| {
        format!(
            "{}: the raster lies within latitudes {beyond} that --tiling {} covers; use \
             --tiling geographic",
            input.display(),
            options.tiling.name(),
        )
    })?;
    // Refused as `mesh` and `contour` refuse it: a warp to a lattice finer than the raster
    // would fill a block from a single sample, and every coarser level is made from it.
    if !tinsmith_raster::WindowReader::open(input, options.band)?.has_valid_cell()? {
        return Err(TerrainError::Options(format!(
            "{}: band {} has no 2x2 block of valid samples, so there is no terrain to write",
            input.display(),
            options.band,
        )));
    }
    // The tiles' lattice is the anchor raster's (the base's, with one), and the input's
    // own level is the first whose lattice is at least as fine as it.
    let below = match &options.base {
        Some(base) => Some(geographic_bounds(&base.path, 1)?),
        None => None,
    };
    let anchor_resolution = below.as_ref().unwrap_or(&bounds).resolution;
    let cells = lattice_cells(anchor_resolution, options.tiling);
    let scheme = Scheme {
        tiling: options.tiling,
        cells,
    };
    let own_level = own_level(bounds.resolution, options.tiling, cells);
    let max_zoom = options.max_zoom.unwrap_or(own_level);
    if options.metadata && options.min_zoom > 0 {
        return Err(TerrainError::Options(format!(
            "--metadata needs --min-zoom 0 (got {}): CesiumJS learns which tiles exist from \
             the metadata of the level-0 tiles",
            options.min_zoom
        )));
    }
    if options.format == TileFormat::ThreeDTiles {
        // CesiumJS requests both root tiles and reads every subtree from the root ones.
        let clash = [
            (options.min_zoom > 0, "--min-zoom above 0"),
            (!options.whole_globe, "--data-only"),
            (options.metadata, "--metadata (a quantized-mesh extension)"),
            (
                options.tiling != Tiling::Geographic,
                "--tiling mercator (Cesium3DTilesTerrainProvider tiles the globe geographically)",
            ),
        ];
        if let Some((_, what)) = clash.iter().find(|(on, _)| *on) {
            return Err(TerrainError::Options(format!(
                "--format 3dtiles cannot be combined with {what}: its pyramid covers the \
                 whole globe from level 0"
            )));
        }
    }
    if options.max_zoom.is_none() && options.min_zoom > max_zoom {
        return Err(TerrainError::Options(format!(
            "--min-zoom {} is above the default --max-zoom {max_zoom} (the raster's own \
             resolution); give --max-zoom too",
            options.min_zoom
        )));
    }
    if options.min_zoom > max_zoom {
        return Err(TerrainError::Options(format!(
            "--min-zoom {} is above --max-zoom {max_zoom}",
            options.min_zoom
        )));
    }
    if max_zoom > MAX_LEVEL {
        return Err(TerrainError::Options(format!(
            "zoom range {}..={max_zoom} is not within 0..={MAX_LEVEL}",
            options.min_zoom
        )));
    }
    let tiles_at = |level: u8| domain(&bounds, scheme, level).tiles();
    let threads = match options.threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    let fits = |level: u8| {
        options.memory_limit.is_none_or(|limit| {
            streaming_bytes_of(&bounds, scheme, own_level, level.max(own_level), threads) <= limit
        })
    };
    let not_overzoomed = |level: u8| {
        level <= own_level.saturating_add(OVERZOOM_LEVELS) || tiles_at(level) <= OVERZOOM_TILES
    };
    // The finest level from --min-zoom up that would run, to name in a refusal.
    let suggestion = || match (options.min_zoom..max_zoom)
        .rev()
        .find(|&l| not_overzoomed(l) && fits(l))
    {
        Some(level) => format!("choose --max-zoom {level} or lower"),
        None => "no --max-zoom helps, since every level is filtered from the raster's own; \
                 make a coarser copy of the input (gdalwarp -tr) for a pyramid this wide"
            .to_string(),
    };
    if !not_overzoomed(max_zoom) {
        return Err(TerrainError::Options(format!(
            "--max-zoom {max_zoom} would write about {} tiles at that level, {} levels finer \
             than the raster's own resolution (level {own_level}): they would only \
             interpolate between its samples, and CesiumJS draws the finest level up close \
             by itself; {}",
            tiles_at(max_zoom),
            max_zoom - own_level,
            suggestion()
        )));
    }
    if let Some(limit) = options.memory_limit {
        // Levels up to the raster's own are filtered from it, so it is always streamed.
        let streamed = max_zoom.max(own_level);
        let need = streaming_bytes_of(&bounds, scheme, own_level, streamed, threads);
        if need > limit && streaming_bytes_of(&bounds, scheme, own_level, streamed, 1) <= limit {
            return Err(TerrainError::Options(format!(
                "{threads} threads would need about {:.1} GB in memory (each warps a band of \
                 level {streamed}) and {:.1} GB is available; use fewer --threads",
                need as f64 / 1e9,
                limit as f64 / 1e9
            )));
        }
        if need > limit {
            return Err(TerrainError::Options(format!(
                "level {streamed} would need about {:.1} GB in memory (its tile rows span \
                 {} tiles) and {:.1} GB is available (the raster's own resolution is level \
                 {own_level}, which every coarser level is filtered from); {}",
                need as f64 / 1e9,
                domain(&bounds, scheme, streamed).width,
                limit as f64 / 1e9,
                suggestion()
            )));
        }
    }
    // The warp works in f32: heights beyond it would be clamped or lost as nodata, so a
    // source that may hold them (Float64, or scaled) is scanned for them first.
    if tinsmith_raster::heights_may_exceed_f32(input, options.band)? {
        let info = tinsmith_raster::open_info(input, options.band)?;
        if let (Some(lo), Some(hi)) = (info.min, info.max) {
            // Each tile's range is checked after the warp; here only what the warp loses.
            let max_abs = lo.abs().max(hi.abs());
            if max_abs >= f64::from(f32::MAX) / 2.0 {
                return Err(TerrainError::Options(format!(
                    "heights up to {max_abs:e} in magnitude are beyond what quantized-mesh \
                     tiles can hold (their height range is stored in f32)"
                )));
            }
        }
    }
    match options.base.as_ref().zip(below) {
        None => Ok(Prepared {
            bounds,
            scheme,
            own_level,
            max_zoom,
            fine: bounds,
        }),
        Some((base, below)) => {
            prepare_base(base, below, bounds, scheme, max_zoom, threads, options)
        }
    }
}

/// Clips `bounds` to the latitudes `tiling` covers; a raster wholly beyond them (or with
/// no extent left) is refused with `message` given "S..N, wholly beyond the S'..N'".
fn clip_to_tiling(
    bounds: &mut GeoBounds,
    tiling: Tiling,
    message: impl FnOnce(String) -> String,
) -> TerrainResult<()> {
    let [south, north] = tiling.latitude_range();
    if bounds.south >= north || bounds.north <= south || bounds.south >= bounds.north {
        return Err(TerrainError::Options(message(format!(
            "{:.4}..{:.4}, wholly beyond the {south:.4}..{north:.4}",
            bounds.south, bounds.north
        ))));
    }
    bounds.south = bounds.south.max(south);
    bounds.north = bounds.north.min(north);
    Ok(())
}

/// The extent and anchor of a pyramid of an input over `fine` (its extent) with `base`
/// (whose extent is `below`) under it: the base's own level is the anchor, over both
/// extents; refuses a base that is not a raster with valid samples in reach of the
/// tiling, or whose own level over both extents would need more memory than the run may
/// use.
fn prepare_base(
    base: &crate::BaseRaster,
    mut below: GeoBounds,
    fine: GeoBounds,
    scheme: Scheme,
    max_zoom: u8,
    threads: usize,
    options: &TerrainOptions,
) -> TerrainResult<Prepared> {
    let path = &base.path;
    clip_to_tiling(&mut below, options.tiling, |beyond| {
        format!(
            "--base {}: the raster lies within latitudes {beyond} that --tiling {} covers",
            path.display(),
            options.tiling.name(),
        )
    })?;
    if !tinsmith_raster::WindowReader::open(path, 1)?.has_valid_cell()? {
        return Err(TerrainError::Options(format!(
            "--base {}: band 1 has no 2x2 block of valid samples",
            path.display(),
        )));
    }
    if tinsmith_raster::heights_may_exceed_f32(path, 1)? {
        return Err(TerrainError::Options(format!(
            "--base {}: its heights may be beyond what quantized-mesh tiles can hold (their \
             height range is stored in f32); give a Float32 or integer copy (gdal_translate \
             -ot Float32)",
            path.display()
        )));
    }
    let anchor = own_level(below.resolution, options.tiling, scheme.cells);
    let bounds = crate::base::union(&below, &fine);
    let need = streaming_bytes_of(&bounds, scheme, anchor, anchor, threads);
    if let Some(limit) = options.memory_limit.filter(|&limit| need > limit) {
        return Err(TerrainError::Options(format!(
            "--base {}: its own level {anchor}, which the levels up to it are filtered from, \
             would need about {:.1} GB in memory over the pyramid's extent (its tile rows span \
             {} tiles) and {:.1} GB is available; make a coarser copy of it (gdalwarp -tr)",
            path.display(),
            need as f64 / 1e9,
            domain(&bounds, scheme, anchor).width,
            limit as f64 / 1e9,
        )));
    }
    Ok(Prepared {
        bounds,
        scheme,
        own_level: anchor,
        max_zoom,
        fine,
    })
}

/// Builds every tile of `block` (a tile of `cut.split`) and of the levels under it down
/// to `max_zoom` (those finer than the anchor only within `fine`), writing them under
/// `out_dir`; returns what was written and the block's samples at the split level when it
/// has any valid one (what the levels above are filtered from).
#[allow(clippy::too_many_arguments)]
pub(super) fn build_block(
    source: &dyn RowSource,
    bounds: &GeoBounds,
    fine: &GeoBounds,
    cut: Cut,
    max_zoom: u8,
    block: TileRect,
    band_rows: Option<u32>,
    store: &dyn TileStore,
    options: &TerrainOptions,
    pool: &rayon::ThreadPool,
    known: &Entries,
) -> TerrainResult<(Written, Option<Vec<f32>>)> {
    let scope = Scope {
        levels: (options.min_zoom.max(cut.split), max_zoom),
        under: Some(block),
        scheme: cut.tiling,
    };
    let mut writer = TileWriter::new(scope, max_zoom, Vec::new(), known, store, options, pool);
    let band = |over: &GeoBounds, z: u8| {
        band_rows.unwrap_or_else(|| band_tile_rows(block_window(over, block, z)))
    };
    // Levels finer than the anchor first, each sampled alone; then the anchor and the
    // levels filtered from it, down to the block's own.
    for z in (cut.anchor + 1..=max_zoom).rev() {
        if !meets(block, domain(fine, cut.tiling, z)) {
            continue;
        }
        let level = |z: u8| {
            block_level(fine, block, z, reach_margin(cut.tiling, z, z))
                .filled_with(options.outside())
        };
        stream_levels(source, &level, (z, z), band(fine, z), pool, &mut writer)?;
    }
    let level = |z: u8| {
        block_level(bounds, block, z, reach_margin(cut.tiling, cut.split, z))
            .filled_with(options.outside())
    };
    let zooms = (cut.split, cut.anchor);
    stream_levels(
        source,
        &level,
        zooms,
        band(bounds, cut.anchor),
        pool,
        &mut writer,
    )?;
    let samples = writer
        .block_samples
        .take()
        .filter(|values| values.iter().any(|v| v.is_finite()));
    Ok((writer.finish(), samples))
}

/// Whether any tile under `block` lies in `rect` (a finer level's), round the globe.
fn meets(block: TileRect, rect: TileRect) -> bool {
    let f = rect.level - block.level;
    let turn = block.tiling.columns(rect.level) as i64;
    let (x0, x1) = (
        i64::from(block.x0) << f,
        i64::from(block.x0 + block.width) << f,
    );
    let (y0, y1) = (block.y0 << f, (block.y0 + block.height) << f);
    let (d0, d1) = (i64::from(rect.x0), i64::from(rect.x0 + rect.width));
    let columns = [-1, 0, 1]
        .iter()
        .any(|k| x0 + k * turn < d1 && d0 < x1 + k * turn);
    columns && y0 < rect.y0 + rect.height && rect.y0 < y1
}

/// The worker pool of a pyramid whose finest streamed level over `bounds` is `finest`.
pub(super) fn worker_pool(
    bounds: &GeoBounds,
    tiling: Scheme,
    finest: u8,
    threads: usize,
) -> TerrainResult<rayon::ThreadPool> {
    // The finest level has the most tiles: more workers than that would idle.
    let tiles = domain(bounds, tiling, finest).tiles();
    let workers = tinsmith_tiling::worker_count(threads, tiles as usize);
    rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .build()
        .map_err(|source| TerrainError::Threads {
            threads: workers,
            source,
        })
}

/// Writes, with `--metadata` (CesiumJS then ignores `available` and requests both root
/// tiles) or a whole globe, the root tiles the raster does not reach, flat, and adds them
/// to `written`.
pub(super) fn write_flat_roots(
    written: &mut Written,
    scheme: Scheme,
    max_zoom: u8,
    store: &dyn TileStore,
    options: &TerrainOptions,
    pool: &rayon::ThreadPool,
    known: &Entries,
) -> TerrainResult<()> {
    if !((options.metadata || options.whole_globe) && options.min_zoom == 0) {
        return Ok(());
    }
    let scope = Scope {
        levels: (0, 0),
        under: None,
        scheme,
    };
    let available = written.available.clone();
    let mut writer = TileWriter::new(scope, max_zoom, available, known, store, options, pool);
    for x in 0..options.tiling.columns(0) as u32 {
        if !written.available[0].contains(&(x, 0)) {
            writer.write_flat_root(x)?;
        }
    }
    written.absorb(writer.finish());
    Ok(())
}

/// The level reports of `written`, `min_zoom ..= max_zoom`, coarsest first (a level
/// without tiles reported empty).
pub(super) fn level_reports(
    written: &Written,
    scheme: Scheme,
    options: &TerrainOptions,
    max_zoom: u8,
) -> Vec<LevelReport> {
    (options.min_zoom..=max_zoom)
        .map(|z| {
            written
                .reports
                .get(usize::from(z))
                .cloned()
                .flatten()
                .unwrap_or_else(|| LevelReport::empty(scheme, z, options.quality))
        })
        .collect()
}

/// Builds the levels above the split, `min_zoom` up to `max_zoom` (if any are), filtered
/// from the split level's `samples`, writing them under `out_dir`. `available` lists the
/// tiles the blocks wrote (the metadata extension of levels 0, 10, 20 lists them).
#[allow(clippy::too_many_arguments)]
pub(super) fn build_top(
    samples: &SplitSamples,
    bounds: &GeoBounds,
    cut: Cut,
    max_zoom: u8,
    available: Available,
    store: &dyn TileStore,
    options: &TerrainOptions,
    pool: &rayon::ThreadPool,
    known: &Entries,
) -> TerrainResult<Written> {
    if cut.split == 0 || options.min_zoom >= cut.split || options.min_zoom > max_zoom {
        return Ok(Written::default());
    }
    let scope = Scope {
        levels: (options.min_zoom, max_zoom.min(cut.split - 1)),
        under: None,
        scheme: cut.tiling,
    };
    let mut writer = TileWriter::new(scope, max_zoom, available, known, store, options, pool);
    let level =
        |z: u8| LevelRows::new(domain(bounds, cut.tiling, z)).filled_with(options.outside());
    let band = band_tile_rows(domain(bounds, cut.tiling, cut.split));
    stream_levels(
        samples,
        &level,
        (options.min_zoom, cut.split),
        band,
        pool,
        &mut writer,
    )?;
    Ok(writer.finish())
}

/// Builds `blocks` (see [`build_block`]), recording each under `out_dir` (its tiles'
/// entries and its samples at the split level) after its tiles; tiles `known` with the
/// same fingerprint are kept. `done` hears how many blocks are finished. Returns what was
/// written and the blocks' samples.
#[allow(clippy::too_many_arguments)]
pub(super) fn build_recorded_blocks(
    source: &dyn RowSource,
    bounds: &GeoBounds,
    fine: &GeoBounds,
    cut: Cut,
    max_zoom: u8,
    blocks: &[TileRect],
    store: &dyn TileStore,
    options: &TerrainOptions,
    pool: &rayon::ThreadPool,
    known: &Entries,
    done: &mut dyn FnMut(usize),
) -> TerrainResult<(Written, SplitSamples)> {
    let mut written = Written::default();
    let mut samples = SplitSamples::default();
    let key = options_key(options);
    for (k, &block) in blocks.iter().enumerate() {
        let (built, values) = build_block(
            source, bounds, fine, cut, max_zoom, block, None, store, options, pool, known,
        )?;
        let id = [cut.tiling.tile_column(cut.split, block.x0), block.y0];
        let name = block_name(cut.split, id);
        if let Some(values) = &values {
            store.put_file(&format!("{name}.samples"), &gzip_samples(values))?;
        }
        let record = BlockRecord {
            options: key.clone(),
            block: id,
            split: cut.split,
            tiles: built.entries.clone(),
            samples: values.is_some(),
        };
        put_record(store, &format!("{name}.json"), &record)?;
        if let Some(values) = values {
            samples.tiles.insert((id[0], id[1]), values);
        }
        written.absorb(built);
        done(k + 1);
    }
    Ok((written, samples))
}

/// Finishes a pyramid whose blocks are `written` (with their `samples`): the levels above
/// the blocks, the flat roots (`--metadata`), their record, and `layer.json` (named
/// `name`) last, unless it holds these bytes already. Tiles `known` with the same
/// fingerprint are kept. Reports each level to `progress`, finest first, and returns the
/// level reports, coarsest first.
///
/// # Errors
/// [`TerrainError::NoTerrain`] when the finest level has no tile with data.
#[allow(clippy::too_many_arguments)]
pub(super) fn finish_pyramid(
    name: &str,
    mut written: Written,
    samples: &SplitSamples,
    bounds: &GeoBounds,
    cut: Cut,
    max_zoom: u8,
    store: &dyn TileStore,
    options: &TerrainOptions,
    pool: &rayon::ThreadPool,
    known: &Entries,
    progress: &mut dyn FnMut(Progress<'_>),
) -> TerrainResult<(Vec<LevelReport>, u64)> {
    let levels = usize::from(max_zoom) + 1;
    written.reports.resize(levels, None);
    written.available.resize(levels, Default::default());
    let available = written.available.clone();
    let mut top = build_top(
        samples, bounds, cut, max_zoom, available, store, options, pool, known,
    )?;
    let before = written.entries.len();
    written.absorb(std::mem::take(&mut top));
    write_flat_roots(
        &mut written,
        cut.tiling,
        max_zoom,
        store,
        options,
        pool,
        known,
    )?;
    let reports = level_reports(&written, cut.tiling, options, max_zoom);
    let finest = reports.last().expect("min_zoom <= max_zoom");
    if finest.tiles == finest.flat_tiles {
        return Err(TerrainError::NoTerrain { level: max_zoom });
    }
    put_record(
        store,
        &top_name(),
        &TopRecord {
            options: options_key(options),
            tiles: written.entries[before..].to_vec(),
        },
    )?;
    // Tiles a previous run wrote that this one did not consider (the input shrank).
    let now: std::collections::HashSet<(u8, u32, u32)> =
        written.entries.iter().map(|e| (e.z, e.x, e.y)).collect();
    for entry in known.values() {
        if entry.written && !now.contains(&(entry.z, entry.x, entry.y)) {
            remove_tile(store, options.format, (entry.z, entry.x, entry.y))?;
        }
    }
    for level in reports.iter().rev() {
        progress(Progress::Level(level));
    }
    if options.format == TileFormat::ThreeDTiles {
        write_tileset(&written, store)?;
        return Ok((reports, written.kept));
    }
    let layer = layer_json(name, options, bounds, max_zoom, &written.available);
    if store.get_file("layer.json")?.as_deref() != Some(layer.as_bytes()) {
        store.put_file("layer.json", layer.as_bytes())?;
    }
    Ok((reports, written.kept))
}

/// Writes the subtrees of the 3D Tiles tiles in `written`, then `tileset.json`.
fn write_tileset(written: &Written, store: &dyn TileStore) -> TerrainResult<()> {
    let deepest = written.metadata.keys().map(|k| k.0).max().unwrap_or(0);
    let files = subtrees(&written.metadata, subtree_levels(deepest)).map_err(|(z, x, y)| {
        TerrainError::Options(format!(
            "tile {z}/{x}/{y} was written without its parent tile, so no 3D Tiles client \
             could reach it"
        ))
    })?;
    let names: std::collections::HashSet<String> = files.iter().map(|(n, _)| n.clone()).collect();
    for (name, bytes) in files {
        if store.get_file(&name)?.as_deref() != Some(&bytes[..]) {
            store.put_file(&name, &bytes)?;
        }
    }
    // Subtrees of an earlier run (an update) that this one no longer has.
    for name in store.list_files("subtrees/")? {
        if !names.contains(&name) {
            store.delete_file(&name)?;
        }
    }
    let tileset = tileset_json(&written.metadata, deepest);
    store.put_file("tileset.json", tileset.as_bytes())?;
    Ok(())
}

/// Every tile entry recorded in `store` (blocks and top), by address: what an update
/// compares against.
pub(super) fn recorded_entries(store: &dyn TileStore) -> TerrainResult<Entries> {
    let mut known = Entries::new();
    let top: Option<TopRecord> = read_record(store, &top_name())?;
    let Some(top) = top else {
        return Err(TerrainError::Options(format!(
            "{}: --update needs a pyramid tinsmith built (with its records in {}/); build \
             it once without --update",
            store.location(),
            RECORDS_DIR
        )));
    };
    for name in store.list_files(&format!("{RECORDS_DIR}/blocks/"))? {
        if !name.ends_with(".json") {
            continue;
        }
        let record: BlockRecord = read_record(store, &name)?.expect("listed just now");
        for tile in record.tiles {
            known.insert((tile.z, tile.x, tile.y), tile);
        }
    }
    for tile in top.tiles {
        known.insert((tile.z, tile.x, tile.y), tile);
    }
    Ok(known)
}

/// Removes the block records in `store` that are not of `blocks` at `cut` (an update cut
/// the pyramid elsewhere).
fn remove_stale_records(store: &dyn TileStore, cut: Cut, blocks: &[TileRect]) -> TerrainResult<()> {
    let wanted: std::collections::HashSet<String> = blocks
        .iter()
        .map(|b| block_name(cut.split, [cut.tiling.tile_column(cut.split, b.x0), b.y0]))
        .collect();
    for name in store.list_files(&format!("{RECORDS_DIR}/blocks/"))? {
        let stem = name
            .strip_suffix(".json")
            .or_else(|| name.strip_suffix(".samples"))
            .unwrap_or(&name);
        if !wanted.contains(stem) {
            store.delete_file(&name)?;
        }
    }
    Ok(())
}

/// The name `layer.json` gives a pyramid of `input`: its file stem.
pub(super) fn layer_name(input: &Path) -> String {
    input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "terrain".into())
}

/// The temporary directory the pyramid is built in, beside `out_dir` (which must not
/// exist, or be an empty directory), with the missing parents made for it.
fn stage_pyramid(out_dir: &Path) -> TerrainResult<StagedDir> {
    let refuse =
        |reason: String| TerrainError::Options(format!("output {}: {reason}", out_dir.display()));
    StagedDir::new(out_dir, true).map_err(|error| match error {
        tinsmith_output::Error::Occupied { reason, .. } => refuse(format!(
            "{reason}; give a new directory (the pyramid is written whole, never mixed \
             with other files)"
        )),
        tinsmith_output::Error::FileInTheWay { file, .. } => refuse(format!(
            "{} is a file, so no directory can be made there",
            file.display()
        )),
        tinsmith_output::Error::Io { source, .. } => TerrainError::Output {
            path: out_dir.to_path_buf(),
            source,
        },
        other => TerrainError::Output {
            path: out_dir.to_path_buf(),
            source: std::io::Error::other(other),
        },
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn layer_bounds_are_in_minus_180_to_180() {
        let bounds = |west: f64, east: f64| {
            super::bounds_array(&tinsmith_raster::GeoBounds {
                west,
                south: 0.0,
                east,
                north: 10.0,
                resolution: 0.1,
            })
        };
        assert_eq!(bounds(530.0, 550.0), [170.0, 0.0, -170.0, 10.0]);
        assert_eq!(bounds(170.0, 190.0), [170.0, 0.0, -170.0, 10.0]);
        assert_eq!(bounds(-180.0, 180.0), [-180.0, 0.0, 180.0, 10.0]);
        assert_eq!(bounds(10.0, 20.0), [10.0, 0.0, 20.0, 10.0]);
        assert_eq!(bounds(180.0, 200.0), [-180.0, 0.0, -160.0, 10.0]);
    }

    use super::*;
    use crate::layer::{metadata_json, rectangles};
    use crate::quantized_mesh::QUANTIZED_MAX;
    use crate::stream::Warp;
    use crate::tms::{max_edge_length, EARTH_RADIUS, LATTICE_CELLS};
    use crate::LEVEL_ZERO_ERROR;
    use std::collections::BTreeSet;
    use std::path::PathBuf;

    #[test]
    fn u_lands_exactly_on_the_edges() {
        for cells in LATTICE_CELLS {
            let scheme = Scheme {
                tiling: Tiling::Geographic,
                cells,
            };
            assert_eq!(scheme.u_per_cell() * cells, u32::from(QUANTIZED_MAX));
        }
    }

    #[test]
    fn coarse_levels_cap_edges_by_the_ellipsoid_sag() {
        // Level 0: bound 77 km allows an arc of 17.8 degrees; a lattice step is 0.83.
        let l0 = max_edge_length(Tiling::Geographic, 217, 0, LEVEL_ZERO_ERROR).unwrap();
        assert_eq!(l0, 21);
        let arc = f64::from(l0) * Tiling::Geographic.step(0, 217).to_radians();
        assert!(EARTH_RADIUS * (1.0 - (arc / 2.0).cos()) <= LEVEL_ZERO_ERROR);
        let arc = f64::from(l0 + 1) * Tiling::Geographic.step(0, 217).to_radians();
        assert!(EARTH_RADIUS * (1.0 - (arc / 2.0).cos()) > LEVEL_ZERO_ERROR);
        // Deep levels: no cap.
        assert_eq!(
            max_edge_length(Tiling::Geographic, 217, 12, LEVEL_ZERO_ERROR / 4096.0),
            None
        );
    }

    #[test]
    fn level_errors_match_cesium() {
        assert!((LEVEL_ZERO_ERROR / 1024.0 - 75.26).abs() < 0.01);
    }

    #[test]
    fn rectangles_merge_rows() {
        let tiles: BTreeSet<(u32, u32)> = [(1, 0), (2, 0), (1, 1), (2, 1), (5, 1)]
            .into_iter()
            .collect();
        let all = [0, u32::MAX];
        assert_eq!(
            rectangles(&tiles, all, all),
            vec![[1, 0, 2, 1], [5, 1, 5, 1]]
        );
        assert_eq!(
            rectangles(&tiles, [2, 9], all),
            vec![[2, 0, 2, 1], [5, 1, 5, 1]]
        );
    }

    /// Every file under `root`, by relative path.
    fn files(root: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
        let mut out = std::collections::BTreeMap::new();
        let mut stack = vec![root.to_path_buf()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else {
                    let bytes = std::fs::read(&path).unwrap();
                    out.insert(path.strip_prefix(root).unwrap().to_path_buf(), bytes);
                }
            }
        }
        out
    }

    #[test]
    fn pyramid_bytes_do_not_depend_on_the_band_height_or_the_cut() {
        // 4 x 3 tiles at level 12 with a hole; level 10 carries the metadata of 11 and 12,
        // so it must see their availability complete although the levels interleave.
        let bounds = GeoBounds {
            west: 10.01,
            south: 45.01,
            east: 10.11,
            north: 45.11,
            resolution: 0.0002,
        };
        let options = TerrainOptions {
            min_zoom: 9,
            max_zoom: Some(12),
            normals: true,
            metadata: true,
            threads: 2,
            ..TerrainOptions::default()
        };
        let levels = same_bytes_for_every_cut(&bounds, &options, &[8, 10, 12, 11]);
        assert_eq!(levels[3].tiles, 12);
    }

    #[test]
    fn a_mercator_pyramid_is_the_same_for_every_cut() {
        // Web Mercator, far north (where a tile's Web Mercator middle is furthest from its
        // latitude middle) and at the equator, cut at the coarsest split and finer ones: the
        // resampled filter reads rows beyond the geographic reach.
        // Near the pole, split 4 levels up from level 9.
        let cases: [([f64; 4], u8, &[u8]); 3] = [
            ([10.01, 69.8, 10.4, 70.3], 11, &[7, 9, 11, 8]),
            ([10.01, -0.2, 10.4, 0.15], 11, &[7, 9, 11, 8]),
            ([10.01, 79.5, 11.5, 80.2], 9, &[5, 6, 9, 7]),
        ];
        for ([west, south, east, north], max_zoom, splits) in cases {
            let options = TerrainOptions {
                min_zoom: 0,
                max_zoom: Some(max_zoom),
                normals: true,
                metadata: true,
                whole_globe: true,
                threads: 2,
                tiling: Tiling::Mercator,
                ..TerrainOptions::default()
            };
            let bounds = GeoBounds {
                west,
                south,
                east,
                north,
                resolution: 0.0007,
            };
            let levels = same_bytes_for_every_cut(&bounds, &options, splits);
            let finest = &levels[usize::from(max_zoom)];
            assert!(finest.tiles > 4 && levels[0].tiles == 1, "{levels:?}");
        }
    }

    /// Builds the pyramid of made-up hills over `bounds` with `options`, cut at each of
    /// the `splits` (the first with bands of one tile row, the others of 100, 1 and 3 in
    /// turn), and checks they all write the same bytes and counts: returns the level
    /// reports.
    fn same_bytes_for_every_cut(
        bounds: &GeoBounds,
        options: &TerrainOptions,
        splits: &[u8],
    ) -> Vec<LevelReport> {
        let source = crate::stream::Hills {
            hole: [
                (bounds.west + bounds.east) / 2.0,
                bounds.south * 0.7 + bounds.north * 0.3,
                (bounds.north - bounds.south) * 0.15,
            ],
        };
        let max_zoom = options.max_zoom.expect("a max zoom");
        let mut outputs = Vec::new();
        for (k, &split) in splits.iter().enumerate() {
            let band_rows = [1, 100, 1, 3][k % 4];
            let dir = tempfile::tempdir().unwrap();
            let cut = Cut {
                tiling: Scheme {
                    tiling: options.tiling,
                    cells: LATTICE_CELLS[0],
                },
                anchor: max_zoom,
                split,
            };
            let (levels, files) = build_in(
                &source,
                bounds,
                cut,
                max_zoom,
                band_rows,
                dir.path(),
                options,
            );
            outputs.push((files, levels));
        }
        let (files, levels) = &outputs[0];
        let tiles = |level: &str| {
            files
                .keys()
                .filter(|p| p.starts_with(level) && p.extension().is_some_and(|e| e == "terrain"))
                .count() as u64
        };
        assert_eq!(
            (options.min_zoom..=max_zoom)
                .map(|z| tiles(&z.to_string()))
                .sum::<u64>(),
            levels.iter().map(|l| l.tiles).sum::<u64>()
        );
        assert!(tiles(&(max_zoom - 2).to_string()) > 0 && tiles(&max_zoom.to_string()) > 0);
        for (k, output) in outputs.iter().enumerate().skip(1) {
            let differ: Vec<_> = (output.0.keys().chain(outputs[0].0.keys()))
                .filter(|p| output.0.get(*p) != outputs[0].0.get(*p))
                .collect();
            assert!(
                differ.is_empty(),
                "split {}: other bytes in {differ:?}",
                splits[k]
            );
            assert!(
                output.1 == outputs[0].1,
                "split {}: other counts",
                splits[k]
            );
        }
        outputs.swap_remove(0).1
    }

    /// The pyramid of `source` cut at `cut`, streamed in bands of `band_rows` tile rows,
    /// into `dir`: its level reports and files (not the records, which say how it was cut).
    fn build_in(
        source: &dyn RowSource,
        bounds: &GeoBounds,
        cut: Cut,
        max_zoom: u8,
        band_rows: u32,
        dir: &Path,
        options: &TerrainOptions,
    ) -> (
        Vec<LevelReport>,
        std::collections::BTreeMap<PathBuf, Vec<u8>>,
    ) {
        let store = DirectoryStore::open(dir).unwrap();
        let pool = worker_pool(bounds, cut.tiling, max_zoom.max(cut.anchor), 2).unwrap();
        let known = Entries::new();
        let mut written = Written::default();
        let mut samples = SplitSamples::default();
        for block in blocks(bounds, cut) {
            let (built, values) = build_block(
                source,
                bounds,
                bounds,
                cut,
                max_zoom,
                block,
                Some(band_rows),
                &store,
                options,
                &pool,
                &known,
            )
            .unwrap();
            if let Some(values) = values {
                samples.tiles.insert(
                    (cut.tiling.tile_column(cut.split, block.x0), block.y0),
                    values,
                );
            }
            written.absorb(built);
        }
        let (mut levels, _) = finish_pyramid(
            "test",
            written,
            &samples,
            bounds,
            cut,
            max_zoom,
            &store,
            options,
            &pool,
            &known,
            &mut |_| {},
        )
        .unwrap();
        for level in &mut levels {
            level.seconds = 0.0;
        }
        let mut files = files(dir);
        files.retain(|p, _| !p.starts_with(RECORDS_DIR));
        (levels, files)
    }

    #[test]
    fn sampled_pyramid_bytes_do_not_depend_on_the_band_height_or_the_cut() {
        // The real sampler: a projected raster at its own level, and a global one (whose
        // columns wrap) two levels finer than its own, in bands of one tile row and of a
        // whole level, cut at two levels.
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        for (input, max_zoom) in [
            ("data/becmodel_dem_bc_albers_50m.tif", 11),
            ("tests/fixtures/etopo5_2deg_i16.tif", 2),
        ] {
            let input = root.join(input);
            let bounds = geographic_bounds(&input, 1).unwrap();
            let source = Warp {
                path: &input,
                band: 1,
                datum: &tinsmith_raster::VerticalDatum::Ellipsoid,
                outside: f32::NAN,
            };
            let options = TerrainOptions {
                max_zoom: Some(max_zoom),
                normals: true,
                threads: 2,
                ..TerrainOptions::default()
            };
            let (scheme, anchor) = own_scheme(&bounds, Tiling::Geographic);
            let coarsest = Cut::coarsest(scheme, anchor);
            let finer = Cut {
                tiling: scheme,
                anchor,
                split: (coarsest.split + 2).min(anchor),
            };
            let mut outputs = Vec::new();
            for (cut, band_rows) in [(coarsest, 1), (finer, 100)] {
                let dir = tempfile::tempdir().unwrap();
                outputs.push(build_in(
                    &source,
                    &bounds,
                    cut,
                    max_zoom,
                    band_rows,
                    dir.path(),
                    &options,
                ));
            }
            let finest = outputs[0].0.last().unwrap();
            assert!(
                finest.tiles > 2 && domain(&bounds, scheme, max_zoom).height > 2,
                "{}",
                input.display()
            );
            assert!(
                outputs[0] == outputs[1],
                "{}: other cuts and bands give other tiles",
                input.display()
            );
        }
    }

    #[test]
    fn a_sampled_globe_is_the_same_for_every_cut() {
        // The 2-degree global ETOPO sampled at level 2 and cut at levels 0, 1 and 2: the
        // blocks' windows at levels 1 and 2 reach a turn east of the first, where the
        // lattice's columns and the tiles' rectangles must be those of the first turn
        // (headers and normals of tiles held a turn east came out an ulp apart).
        let input =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/etopo5_2deg_i16.tif");
        let bounds = geographic_bounds(&input, 1).unwrap();
        let source = Warp {
            path: &input,
            band: 1,
            datum: &tinsmith_raster::VerticalDatum::Ellipsoid,
            outside: f32::NAN,
        };
        let options = TerrainOptions {
            max_zoom: Some(2),
            normals: true,
            threads: 2,
            ..TerrainOptions::default()
        };
        let cuts = [(0, 100), (0, 1), (1, 1), (2, 3)];
        let outputs: Vec<_> = cuts
            .iter()
            .map(|&(split, band_rows)| {
                let dir = tempfile::tempdir().unwrap();
                let cut = Cut {
                    tiling: Scheme::GEOGRAPHIC,
                    anchor: 2,
                    split,
                };
                build_in(&source, &bounds, cut, 2, band_rows, dir.path(), &options)
            })
            .collect();
        assert_eq!(outputs[0].0.last().unwrap().tiles, 32);
        for (k, output) in outputs.iter().enumerate().skip(1) {
            let differ: Vec<_> = (output.1.keys().chain(outputs[0].1.keys()))
                .filter(|p| output.1.get(*p) != outputs[0].1.get(*p))
                .collect();
            assert!(
                differ.is_empty(),
                "cut {:?}: other bytes in {differ:?}",
                cuts[k]
            );
        }
    }

    #[test]
    fn metadata_lists_levels_below() {
        let mut available: Available = vec![BTreeSet::new(); 3];
        available[1].insert((0, 0));
        available[1].insert((1, 1));
        available[2].insert((3, 2));
        assert_eq!(
            metadata_json(&available, 0, 0, 0),
            r#"{"available":[[{"startX":0,"startY":0,"endX":0,"endY":0},{"startX":1,"startY":1,"endX":1,"endY":1}],[{"startX":3,"startY":2,"endX":3,"endY":2}]]}"#
        );
    }
}
