//! A Cesium quantized-mesh terrain pyramid: geographic TMS tiles (EPSG:4326, 2x1 root
//! tiles, y = 0 in the south), each decimated within `quality x e(level)`, with shared
//! edges simplified once so that same-level neighbours keep identical edge vertices.

use std::collections::BTreeSet;
use std::ops::Range;
use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use tinsmith_output::StagedDir;
use tinsmith_raster::{geographic_bounds, GeoBounds};

use crate::budget::LevelBudget;
use crate::layer::{write_layer_json, Available};
use crate::rows::LevelRows;
use crate::stream::{band_tile_rows, stream_levels, LevelSink, RowSource, Warp};
use crate::tile::{build_tile, TileOut};
use crate::tms::{bounds_array, step, TILE_CELLS};
use crate::{TerrainError, TerrainResult, METADATA_AVAILABILITY};

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
        }
    }
}

/// About how many bytes streaming a pyramid over `bounds` down to `max_zoom` takes: the
/// finest level's bands of whole tile rows (one per thread in the warp, a few held),
/// 4 bytes a sample, with the coarser levels' rows (a third more), and the record of every
/// tile written (for `layer.json`'s availability, about 48 bytes a tile). An estimate for
/// refusing hopeless runs (a small raster at a far finer level than its own), not a bound.
pub fn streaming_bytes(bounds: &GeoBounds, max_zoom: u8, threads: usize) -> u64 {
    let finest = LevelRows::new(bounds, max_zoom);
    let band = (finest.width as u64 * u64::from(TILE_CELLS + 1)).max(1 << 22);
    let bands = threads.max(1) as u64 + 3;
    let rows = band.saturating_mul(bands).saturating_mul(4);
    let tiles = u64::from(finest.tiles_x) * u64::from(finest.tiles_y);
    rows.saturating_add(tiles.saturating_mul(48))
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
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
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

/// What [`build_terrain`] produced.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TerrainReport {
    /// The input's extent in EPSG:4326, `[west, south, east, north]`: west > east across
    /// the antimeridian.
    pub bounds: [f64; 4],
    /// Coarsest level.
    pub min_zoom: u8,
    /// Finest level.
    pub max_zoom: u8,
    /// Per level, coarsest first.
    pub levels: Vec<LevelReport>,
}

/// Builds the pyramid of `input` into `out_dir`: `z/x/y.terrain` tiles and `layer.json`.
///
/// # Guarantees
/// - **Bound.** At every valid sample of a tile's grid (its `(TILE_CELLS + 1)^2` lattice
///   points, taken from the level's raster), the decoded tile (float32 min/max, 16-bit
///   heights) is within `quality x e(level)` of the sample, or within half the level's
///   height quantum when that is larger (reported as `achieved_bound`); checked for every
///   tile by `tinsmith-verify` before the tile is written.
/// - **Stitching.** Same-level neighbours have the same vertices along their shared edge,
///   at the same positions, with heights on the level's common lattice (multiples of
///   `height_step`), so they decode to the same heights.
/// - **Determinism.** The same input and options give the same bytes for any `threads`.
/// - Tiles without a valid cell are not written and not listed in `available`.
/// - **Memory.** Bounded by a few bands of tile rows per level (a band is at most 2^22
///   samples of the finest level, or one tile row when a row is wider), plus one band per
///   thread during the warp: it does not grow with the raster's height.
///
/// The finest level is warped from the input with GDAL (bilinear), band by band; each
/// coarser level is the finer one smoothed and halved, row by row as the finer rows
/// arrive. Each level's height quantum depends on its widest tile, and the rounding slack
/// of every level on the finest level's largest |height|, both known only once the level
/// has been seen whole, so the levels are streamed twice: once for these statistics, once
/// for the tiles (the input is read twice, never held whole).
pub fn build_terrain(
    input: &Path,
    out_dir: &Path,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(&LevelReport),
) -> TerrainResult<TerrainReport> {
    if !(options.quality > 0.0 && options.quality <= MAX_QUALITY) {
        return Err(TerrainError::Options(format!(
            "--quality must be a positive number up to {MAX_QUALITY:e}, got {:?}",
            options.quality
        )));
    }
    let bounds = geographic_bounds(input, options.band)?;
    if bounds.south >= bounds.north {
        return Err(TerrainError::Options(
            "the raster lies outside latitudes -90..90 in EPSG:4326: no tile can hold it \
             (is its georeferencing right?)"
                .into(),
        ));
    }
    // Refused as `mesh` and `contour` refuse it: a warp to a lattice finer than the raster
    // would fill a block from a single sample, and every coarser level is made from it.
    if !tinsmith_raster::WindowReader::open(input, options.band)?.has_valid_cell()? {
        return Err(TerrainError::Options(format!(
            "{}: band {} has no 2x2 block of valid samples, so there is no terrain to write",
            input.display(),
            options.band,
        )));
    }
    // The first level whose lattice is at least as fine as the raster.
    let own_level = (0..MAX_LEVEL)
        .find(|&l| step(l) <= bounds.resolution * (1.0 + 1e-9))
        .unwrap_or(MAX_LEVEL);
    let max_zoom = options.max_zoom.unwrap_or(own_level);
    if options.metadata && options.min_zoom > 0 {
        return Err(TerrainError::Options(format!(
            "--metadata needs --min-zoom 0 (got {}): CesiumJS learns which tiles exist from \
             the metadata of the level-0 tiles",
            options.min_zoom
        )));
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
    let tiles_at = |level: u8| {
        let rows = LevelRows::new(&bounds, level);
        u64::from(rows.tiles_x) * u64::from(rows.tiles_y)
    };
    let threads = match options.threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    let fits = |level: u8| {
        options
            .memory_limit
            .is_none_or(|limit| streaming_bytes(&bounds, level.max(own_level), threads) <= limit)
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
        let need = streaming_bytes(&bounds, streamed, threads);
        if need > limit && streaming_bytes(&bounds, streamed, 1) <= limit {
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
                LevelRows::new(&bounds, streamed).tiles_x,
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
    // All or nothing: the pyramid is built in a temporary directory beside `out_dir` and
    // renamed into place at the end; a failure (or nothing to write) leaves no trace.
    let staging = stage_pyramid(out_dir)?;
    let source = Warp {
        path: input,
        band: options.band,
    };
    let (levels, available) = build_pyramid(
        &source,
        &bounds,
        own_level,
        max_zoom,
        None,
        staging.path(),
        options,
        progress,
    )?;
    // The coarser levels are made from the finest, each reaching a sample further out
    // (see `LevelRows::coarser_rows`): without a triangle at the finest level they would
    // only smear samples that hold none (a single valid sample, a single row) into
    // terrain, where `mesh` and `contour` find nothing to triangulate.
    let finest = levels.last().expect("min_zoom <= max_zoom");
    if finest.tiles == finest.flat_tiles {
        let hint = if options.max_zoom.is_some() {
            " (at this --max-zoom the tile samples may be too far apart for the raster's \
             extent: try a larger one)"
        } else {
            ""
        };
        return Err(TerrainError::Options(format!(
            "{}: band {} has no tile with a 2x2 block of valid samples at level {max_zoom}, the \
             finest (the coarser levels are made from it), so there is no terrain to write{hint}",
            input.display(),
            options.band,
        )));
    }
    write_layer_json(
        input,
        staging.path(),
        options,
        &bounds,
        max_zoom,
        &available,
    )?;
    staging.commit().map_err(|source| TerrainError::Output {
        path: out_dir.to_path_buf(),
        source,
    })?;
    Ok(TerrainReport {
        bounds: bounds_array(&bounds),
        min_zoom: options.min_zoom,
        max_zoom,
        levels,
    })
}

/// The tiles of [`build_terrain`] from `source`: levels finer than `anchor` each sampled
/// from the source alone, finest first, then `anchor` and the levels filtered down from
/// it (see [`stream_levels`]); levels beyond `max_zoom` are made but not written. Each
/// level is read in bands of `band_rows` tile rows (default: [`band_tile_rows`]). Returns
/// the level reports, coarsest first, and the tiles written.
#[allow(clippy::too_many_arguments)]
fn build_pyramid(
    source: &dyn RowSource,
    bounds: &GeoBounds,
    anchor: u8,
    max_zoom: u8,
    band_rows: Option<u32>,
    out_dir: &Path,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(&LevelReport),
) -> TerrainResult<(Vec<LevelReport>, Available)> {
    // The finest level has the most tiles: more workers than that would idle.
    let finest = LevelRows::new(bounds, max_zoom.max(anchor));
    let tiles = finest.tiles_x as usize * finest.tiles_y as usize;
    let workers = tinsmith_tiling::worker_count(options.threads, tiles);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .build()
        .map_err(|source| TerrainError::Threads {
            threads: workers,
            source,
        })?;
    let band = |level: u8| band_rows.unwrap_or_else(|| band_tile_rows(bounds, level));
    let mut writer = TileWriter::new(max_zoom, out_dir, options, &pool, progress);
    for z in (anchor + 1..=max_zoom).rev() {
        stream_levels(source, bounds, (z, z), band(z), &pool, &mut writer)?;
    }
    if options.min_zoom <= anchor {
        let zooms = (options.min_zoom, anchor);
        stream_levels(source, bounds, zooms, band(anchor), &pool, &mut writer)?;
    }
    let mut levels = writer.finished;
    levels.reverse();
    Ok((levels, writer.available))
}

/// The tiles of tile rows `tile_rows` (local) of a level, in TMS row then column order.
fn tiles_of(level: &LevelRows, tile_rows: Range<u32>) -> Vec<(u32, u32)> {
    tile_rows
        .flat_map(|j| (0..level.tiles_x).map(move |i| (level.tx0 + i, level.ty0 + j)))
        .collect()
}

/// Builds, checks and writes the tiles, row by row of each level.
struct TileWriter<'a> {
    max_zoom: u8,
    out_dir: &'a Path,
    options: &'a TerrainOptions,
    pool: &'a rayon::ThreadPool,
    progress: &'a mut dyn FnMut(&LevelReport),
    budgets: Vec<LevelBudget>,
    /// Per level, while it is being written.
    reports: Vec<LevelReport>,
    available: Available,
    /// Finished levels, finest first.
    finished: Vec<LevelReport>,
}

impl<'a> TileWriter<'a> {
    fn new(
        max_zoom: u8,
        out_dir: &'a Path,
        options: &'a TerrainOptions,
        pool: &'a rayon::ThreadPool,
        progress: &'a mut dyn FnMut(&LevelReport),
    ) -> Self {
        let budgets: Vec<LevelBudget> = (0..=max_zoom)
            .map(|z| LevelBudget::new(z, options.quality))
            .collect();
        let reports = budgets
            .iter()
            .zip(0..)
            .map(|(budget, level)| LevelReport {
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
            })
            .collect();
        TileWriter {
            max_zoom,
            out_dir,
            options,
            pool,
            progress,
            budgets,
            reports,
            available: vec![BTreeSet::new(); usize::from(max_zoom) + 1],
            finished: Vec::new(),
        }
    }

    /// Whether `level` is written (levels between `max_zoom` and the anchor are only
    /// filtered through).
    fn writes(&self, level: u8) -> bool {
        (self.options.min_zoom..=self.max_zoom).contains(&level)
    }
}

impl LevelSink for TileWriter<'_> {
    fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()> {
        let z = level.level;
        if !self.writes(z) {
            return Ok(());
        }
        let t = Instant::now();
        let tiles = tiles_of(level, tile_rows);
        let budget = &self.budgets[usize::from(z)];
        let options = self.options;
        // Finer levels inside these tiles' footprints are complete (see `stream_levels`).
        let metadata_available = if options.metadata && z.is_multiple_of(METADATA_AVAILABILITY) {
            Some(&self.available)
        } else {
            None
        };
        let results: Vec<TerrainResult<Option<TileOut>>> = self.pool.install(|| {
            tiles
                .par_iter()
                .map(|&(x, y)| build_tile(level, x, y, budget, options, metadata_available))
                .collect()
        });
        for result in results {
            match result? {
                Some(tile) => self.write(z, &tile)?,
                None => self.reports[usize::from(z)].empty_tiles += 1,
            }
        }
        self.reports[usize::from(z)].seconds += t.elapsed().as_secs_f64();
        Ok(())
    }

    fn level_done(&mut self, level: u8, seconds: f64) -> TerrainResult<()> {
        if !self.writes(level) {
            return Ok(());
        }
        let z = usize::from(level);
        if level == 0 && self.options.metadata {
            // With metadataAvailability CesiumJS ignores `available` and requests both
            // root tiles: one the raster does not reach is written flat (no subtree).
            for x in 0..2 {
                if self.available[0].contains(&(x, 0)) {
                    continue;
                }
                let flat = LevelRows::flat_tile(0, x, 0);
                let budget = &self.budgets[0];
                let tile = build_tile(&flat, x, 0, budget, self.options, Some(&self.available))?
                    .expect("a flat tile has cells");
                self.write(0, &tile)?;
                self.reports[0].flat_tiles += 1;
            }
        }
        let report = &mut self.reports[z];
        report.seconds += seconds;
        (self.progress)(report);
        self.finished.push(report.clone());
        Ok(())
    }
}

impl TileWriter<'_> {
    /// Writes a tile of level `z` into the staging directory and counts it.
    fn write(&mut self, z: u8, tile: &TileOut) -> TerrainResult<()> {
        let dir = self.out_dir.join(z.to_string()).join(tile.x.to_string());
        if tinsmith_output::interrupted() {
            // The staging directory is being removed: add nothing to it.
            return Err(TerrainError::Output {
                path: dir,
                source: std::io::Error::from(std::io::ErrorKind::Interrupted),
            });
        }
        std::fs::create_dir_all(&dir).map_err(|source| TerrainError::Output {
            path: dir.clone(),
            source,
        })?;
        write_atomic(&dir.join(format!("{}.terrain", tile.y)), &tile.bytes)?;
        self.available[usize::from(z)].insert((tile.x, tile.y));
        let report = &mut self.reports[usize::from(z)];
        report.tiles += 1;
        report.bytes += tile.bytes.len() as u64;
        report.vertices += tile.vertices as u64;
        report.triangles += tile.triangles as u64;
        report.measured_max_error = report.measured_max_error.max(tile.max_error);
        report.achieved_bound = report.achieved_bound.max(tile.verified_bound);
        Ok(())
    }
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

/// Writes `bytes` to `path` (in the staging directory) through a temporary file renamed
/// over it.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> TerrainResult<()> {
    tinsmith_output::write_bytes_atomically(path, bytes).map_err(|source| TerrainError::Output {
        path: path.to_path_buf(),
        source,
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
    use crate::tms::{max_edge_length, EARTH_RADIUS, U_PER_CELL};
    use crate::LEVEL_ZERO_ERROR;
    use std::path::PathBuf;

    #[test]
    fn u_lands_exactly_on_the_edges() {
        assert_eq!(U_PER_CELL * TILE_CELLS, u32::from(QUANTIZED_MAX));
    }

    #[test]
    fn coarse_levels_cap_edges_by_the_ellipsoid_sag() {
        // Level 0: bound 77 km allows an arc of 17.8 degrees; a lattice step is 0.83.
        let l0 = max_edge_length(0, LEVEL_ZERO_ERROR).unwrap();
        assert_eq!(l0, 21);
        let arc = f64::from(l0) * step(0).to_radians();
        assert!(EARTH_RADIUS * (1.0 - (arc / 2.0).cos()) <= LEVEL_ZERO_ERROR);
        let arc = f64::from(l0 + 1) * step(0).to_radians();
        assert!(EARTH_RADIUS * (1.0 - (arc / 2.0).cos()) > LEVEL_ZERO_ERROR);
        // Deep levels: no cap.
        assert_eq!(max_edge_length(12, LEVEL_ZERO_ERROR / 4096.0), None);
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
    fn pyramid_bytes_do_not_depend_on_the_band_height() {
        // 4 x 3 tiles at level 12 with a hole; level 10 carries the metadata of 11 and 12,
        // so it must see their availability complete although the levels interleave.
        let bounds = GeoBounds {
            west: 10.01,
            south: 45.01,
            east: 10.11,
            north: 45.11,
            resolution: 0.0002,
        };
        let source = crate::stream::Hills {
            hole: [10.06, 45.04, 0.015],
        };
        let options = TerrainOptions {
            min_zoom: 9,
            max_zoom: Some(12),
            normals: true,
            metadata: true,
            threads: 2,
            ..TerrainOptions::default()
        };
        let mut outputs = Vec::new();
        for band_rows in [1, 100] {
            let dir = tempfile::tempdir().unwrap();
            let mut finished = Vec::new();
            let (mut levels, available) = build_pyramid(
                &source,
                &bounds,
                12,
                12,
                Some(band_rows),
                dir.path(),
                &options,
                &mut |level| finished.push(level.level),
            )
            .unwrap();
            assert_eq!(finished, [12, 11, 10, 9]);
            for level in &mut levels {
                level.seconds = 0.0;
            }
            outputs.push((files(dir.path()), levels, available));
        }
        let (files, levels, available) = &outputs[0];
        assert_eq!(levels[3].tiles, 12);
        assert_eq!(
            files.len() as u64,
            levels.iter().map(|l| l.tiles).sum::<u64>()
        );
        let level_10 = &available[10];
        assert!(!level_10.is_empty() && !available[12].is_empty());
        assert!(
            outputs[0] == outputs[1],
            "bands of 1 and 100 tile rows differ"
        );
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
