//! A Cesium quantized-mesh terrain pyramid: geographic TMS tiles (EPSG:4326, 2x1 root
//! tiles, y = 0 in the south), each decimated within `quality x e(level)`, with shared
//! edges simplified once so that same-level neighbours keep identical edge vertices.

mod rows;
mod stream;

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use tinsmith_core::{decimate_with_border, DecimationOptions, Grid, VertexHeights};
use tinsmith_export::{gzip, GeoRectangle, QuantizedMeshTile, QUANTIZED_MAX};
use tinsmith_raster::{geographic_bounds, GeoBounds};
use tinsmith_verify::{GridRef, MeshRef, VerifyOptions};

use crate::edge::{edge_limit, edge_span, EdgeProfile};
use rows::LevelRows;
use stream::{band_tile_rows, stream_levels, LevelSink, RowSource, Warp};

/// Cesium's level-zero geometric error for the geographic scheme, in metres:
/// `maximumRadius * 2 pi * 0.25 / (65 * 2)` (`TerrainProvider`
/// `getEstimatedLevelZeroGeometricErrorForAHeightmap`). Level L allows `e0 / 2^L`.
pub const LEVEL_ZERO_ERROR: f64 = 77_067.339_771_939_23;

/// Cells along each side of a tile's sample grid: each tile samples
/// `(TILE_CELLS + 1)^2` lattice points. 217 divides 32767 (= 7 x 31 x 151), so sample `i`
/// is at `u = 151 i` exactly: decoded vertices sit exactly on their source samples.
pub const TILE_CELLS: u32 = 217;

/// `u` (and `v`) per cell of the tile grid.
const U_PER_CELL: u32 = QUANTIZED_MAX as u32 / TILE_CELLS;

/// Levels whose tiles carry the metadata extension: 0, N, 2N, ... (`metadataAvailability`).
pub const METADATA_AVAILABILITY: u8 = 10;

/// The largest `--quality`: the level-0 bound is then 7.7e10 m, beyond any height; larger
/// values only risk overflowing the bounds.
const MAX_QUALITY: f64 = 1e6;

/// The finest level [`build_terrain`] will go to.
pub const MAX_LEVEL: u8 = 24;

/// The smallest height quantum (2^-8 m), so that tile minima stay exact in float32.
const MIN_HEIGHT_STEP: f64 = 1.0 / 256.0;

/// What can go wrong while building a pyramid.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TerrainError {
    /// Reading or reprojecting the input failed.
    #[error(transparent)]
    Raster(#[from] tinsmith_raster::Error),
    /// The options make no sense (the message says which).
    #[error("{0}")]
    Options(String),
    /// Heights (largest magnitude, widest range of a tile) beyond what quantized-mesh
    /// tiles, whose height ranges are stored in `f32`, can hold.
    #[error(
        "heights up to {max_abs:e} in magnitude (tiles spanning up to {widest:e}) are beyond what \
         quantized-mesh tiles can hold (their height range is stored in f32)"
    )]
    HeightsBeyondF32 {
        /// The largest magnitude of a valid height.
        max_abs: f64,
        /// The widest range of valid heights of a tile.
        widest: f64,
    },
    /// The thread pool could not start.
    #[error("cannot start {threads} worker threads")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Rayon's reason.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
    /// The core refused a tile.
    #[error("tile {z}/{x}/{y}: decimation failed")]
    Decimate {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The core's reason.
        #[source]
        source: tinsmith_core::Error,
    },
    /// The verifier refused a tile, or found it outside the bound (an internal error).
    #[error("tile {z}/{x}/{y}: verification failed ({problems})")]
    Verify {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// What the verifier found.
        problems: String,
    },
    /// The encoder refused a tile (an internal error).
    #[error("tile {z}/{x}/{y}: encoding failed")]
    Encode {
        /// Level.
        z: u8,
        /// Column.
        x: u32,
        /// TMS row.
        y: u32,
        /// The encoder's reason.
        #[source]
        source: tinsmith_export::EncodeError,
    },
    /// Writing the output failed.
    #[error("{}: cannot write", path.display())]
    Output {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

/// Result of [`build_terrain`].
pub type TerrainResult<T> = std::result::Result<T, TerrainError>;

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

/// Lattice spacing of a level, in degrees.
fn step(level: u8) -> f64 {
    180.0 / (f64::from(TILE_CELLS) * (1u64 << level) as f64)
}

/// WGS84 semi-major axis, metres.
const EARTH_RADIUS: f64 = 6_378_137.0;

/// The longest triangle edge, in lattice spacings of `level`, whose chord sinks no deeper
/// than `bound` metres below the ellipsoid: CesiumJS draws each triangle flat between its
/// ECEF corners, so an edge spanning `t` radians of arc cuts `R (1 - cos(t / 2))` below the
/// surface, an error the height check (made in longitude/latitude) does not see. Measured
/// along the equator (where a lattice step spans the most arc); `None` when even the
/// tile's diagonal is short enough.
fn max_edge_length(level: u8, bound: f64) -> Option<u32> {
    let arc = 2.0 * (1.0 - (bound / EARTH_RADIUS).min(1.0)).acos();
    let spacing = step(level).to_radians();
    let length = (arc / spacing).floor();
    if length >= f64::from(TILE_CELLS) * std::f64::consts::SQRT_2 {
        None
    } else {
        Some((length as u32).max(2))
    }
}

/// `[west, south, east, north]` in degrees, longitudes in [-180, 180]: across the
/// antimeridian `east` is wrapped back below 180, so west > east (as GeoJSON and TileJSON
/// bounding boxes have it); a raster wholly east of 180 has both wrapped.
fn bounds_array(bounds: &GeoBounds) -> [f64; 4] {
    // Into -180..180 by whole turns (a raster given on 530..550° too); an east edge at
    // 180° stays there.
    let wrap = |lon: f64, east: bool| match (lon + 180.0).rem_euclid(360.0) - 180.0 {
        w if east && w == -180.0 => 180.0,
        w => w,
    };
    [
        wrap(bounds.west, false),
        bounds.south,
        wrap(bounds.east, true),
        bounds.north,
    ]
}

/// The tile column of lattice tile column `x` (which is past the last column across the
/// antimeridian, see [`tile_range`]).
fn tile_column(z: u8, x: u32) -> u32 {
    x % (2u32 << z)
}

/// The tile rectangle `z/x/y` (TMS y) in degrees (east of 180 for `x` past the last
/// column: the same tile a turn east).
pub fn tile_rectangle(z: u8, x: u32, y: u32) -> GeoRectangle {
    let size = 180.0 / (1u64 << z) as f64;
    GeoRectangle {
        west: -180.0 + f64::from(x) * size,
        south: -90.0 + f64::from(y) * size,
        east: -180.0 + f64::from(x + 1) * size,
        north: -90.0 + f64::from(y + 1) * size,
    }
}

/// The tiles of `level` that the bounds touch: columns and rows, inclusive. Across the
/// antimeridian the last column is past the level's last (`2^(level+1)` columns): column
/// `x` is then tile `x mod 2^(level+1)` (see [`tile_column`]), at most one full turn.
fn tile_range(bounds: &GeoBounds, level: u8) -> ([u32; 2], [u32; 2]) {
    let n = 1u64 << level;
    let size = 180.0 / n as f64;
    let clamp = |v: f64, max: u64| (v.floor().max(0.0) as u64).min(max - 1) as u32;
    let west = clamp((bounds.west + 180.0) / size, 2 * n);
    let x = [
        west,
        clamp((bounds.east + 180.0) / size, u64::from(west) + 2 * n),
    ];
    let y = [
        clamp((bounds.south + 90.0) / size, n),
        clamp((bounds.north + 90.0) / size, n),
    ];
    (x, y)
}

/// The level's bound and its height quantum.
#[derive(Debug, Clone, Copy)]
struct LevelBudget {
    /// The bound asked for, `quality x e(level)`.
    bound: f64,
    /// The height quantum.
    step: f64,
    /// Longest edge, in lattice spacings (see [`max_edge_length`]).
    max_edge: Option<u32>,
    /// What decimation may use: the bound less the quantization error (half a step).
    decimation: f64,
    /// What the verifier checks: the bound, or half a step (and a margin) when larger.
    verify: f64,
    /// The finest level's largest |height| (every level's rounding slack).
    max_abs: f64,
}

/// How many 16-bit height quanta a tile gives each height step: the largest power of two
/// up to 2^14 that keeps `top` steps (its highest vertex above its minimum, `k_min`
/// steps above 0) within 32767 quanta, and its maximum height exact in float32
/// (`k_min * quanta + 32767` below 2^24 in magnitude). The header's maximum, the top of
/// the 16-bit range, is then within twice the tile's own height range (plus a step) instead
/// of 32767 steps up, which the level's widest tile sets; CesiumJS builds each tile's
/// bounding box from it. Heights stay multiples of the step, exactly, as neighbours
/// decode them.
fn quanta_per_step(k_min: f64, top: f64) -> u32 {
    let mut quanta = 1u32;
    while quanta < 1 << 14
        && top * f64::from(2 * quanta) <= f64::from(QUANTIZED_MAX)
        && k_min.abs() * f64::from(2 * quanta) + f64::from(QUANTIZED_MAX) < f64::from(1u32 << 24)
    {
        quanta *= 2;
    }
    quanta
}

/// One tile done on a worker.
struct TileOut {
    x: u32,
    y: u32,
    bytes: Vec<u8>,
    vertices: usize,
    triangles: usize,
    max_error: f64,
}

/// Which tiles exist, per level.
type Available = Vec<BTreeSet<(u32, u32)>>;

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
            .is_none_or(|limit| streaming_bytes(&bounds, level, threads) <= limit)
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
        None => format!(
            "no level from --min-zoom {} up would run here",
            options.min_zoom
        ),
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
        let need = streaming_bytes(&bounds, max_zoom, threads);
        if need > limit && streaming_bytes(&bounds, max_zoom, 1) <= limit {
            return Err(TerrainError::Options(format!(
                "{threads} threads would need about {:.1} GB in memory (each warps a band of \
                 level {max_zoom}) and {:.1} GB is available; use fewer --threads",
                need as f64 / 1e9,
                limit as f64 / 1e9
            )));
        }
        if need > limit {
            return Err(TerrainError::Options(format!(
                "level {max_zoom} would need about {:.1} GB in memory (its tile rows span \
                 {} tiles) and {:.1} GB is available (the raster's own resolution is level \
                 {own_level}); {}",
                need as f64 / 1e9,
                LevelRows::new(&bounds, max_zoom).tiles_x,
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
    let mut staging = Staging::new(out_dir)?;
    let source = Warp {
        path: input,
        band: options.band,
    };
    let band_rows = band_tile_rows(&bounds, max_zoom);
    let (levels, available) = build_pyramid(
        &source,
        &bounds,
        max_zoom,
        band_rows,
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
    staging.finish(out_dir)?;
    Ok(TerrainReport {
        bounds: bounds_array(&bounds),
        min_zoom: options.min_zoom,
        max_zoom,
        levels,
    })
}

/// The temporary directory a pyramid is built in, beside `out_dir` (which must not exist,
/// or be an empty directory), and the missing parents made for it, as `mkdir -p` would.
/// Dropped unfinished (an error), it removes the directory and the parents it made while
/// they are empty; on a signal, the pending-output registry does the same.
struct Staging {
    temp: Option<tempfile::TempDir>,
    _pending: tinsmith_export::PendingGuard,
    /// The parent directories made here, deepest first, and their registration; `None`
    /// once the pyramid is in place.
    made: Option<(Vec<PathBuf>, tinsmith_export::MadeDirsGuard)>,
}

impl Staging {
    fn new(out_dir: &Path) -> TerrainResult<Staging> {
        let refuse = |reason: String| {
            TerrainError::Options(format!("output {}: {reason}", out_dir.display()))
        };
        if let Some(reason) = crate::per_tile::occupied_reason(out_dir) {
            return Err(refuse(format!(
                "{reason}; give a new directory (the pyramid is written whole, never mixed \
                 with other files)"
            )));
        }
        let (parent, file_in_the_way) = tinsmith_export::output_parent(out_dir);
        if let Some(file) = file_in_the_way {
            return Err(refuse(format!(
                "{} is a file, so no directory can be made there",
                file.display()
            )));
        }
        let output = |source| TerrainError::Output {
            path: out_dir.to_path_buf(),
            source,
        };
        let made: Vec<PathBuf> = parent
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        let guard = tinsmith_export::track_made_dirs(&made);
        let temp = std::fs::create_dir_all(parent)
            .and_then(|()| tinsmith_export::output_temp_dir(parent))
            .map_err(|source| {
                remove_empty(&made);
                output(source)
            })?;
        let staging = Staging {
            _pending: tinsmith_export::track_pending(temp.path()),
            temp: Some(temp),
            made: Some((made, guard)),
        };
        if tinsmith_export::interrupted() {
            // The signal handler may have passed already: dropping `staging` removes it.
            return Err(output(std::io::Error::from(
                std::io::ErrorKind::Interrupted,
            )));
        }
        Ok(staging)
    }

    fn path(&self) -> &Path {
        self.temp.as_ref().expect("not finished").path()
    }

    /// Renames the directory to `out_dir`; on failure it is removed (with the parents
    /// made for it, when dropped).
    fn finish(&mut self, out_dir: &Path) -> TerrainResult<()> {
        let staged = self.temp.take().expect("finished once").keep();
        match std::fs::rename(&staged, out_dir) {
            Ok(()) => {
                self.made = None;
                Ok(())
            }
            Err(source) => {
                let _ = std::fs::remove_dir_all(&staged);
                Err(TerrainError::Output {
                    path: out_dir.to_path_buf(),
                    source,
                })
            }
        }
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        drop(self.temp.take());
        if let Some((made, _)) = &self.made {
            remove_empty(made);
        }
    }
}

/// Removes directories `made` (deepest first) while they are empty.
fn remove_empty(made: &[PathBuf]) {
    for dir in made {
        if std::fs::remove_dir(dir).is_err() {
            break;
        }
    }
}

/// The tiles of [`build_terrain`] from `source`, its finest level read in bands of
/// `band_rows` tile rows: the level reports, coarsest first, and the tiles written.
fn build_pyramid(
    source: &dyn RowSource,
    bounds: &GeoBounds,
    max_zoom: u8,
    band_rows: u32,
    out_dir: &Path,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(&LevelReport),
) -> TerrainResult<(Vec<LevelReport>, Available)> {
    // The finest level has the most tiles: more workers than that would idle.
    let finest = LevelRows::new(bounds, max_zoom);
    let tiles = finest.tiles_x as usize * finest.tiles_y as usize;
    let workers = crate::engine::worker_count(options.threads, tiles);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .build()
        .map_err(|source| TerrainError::Threads {
            threads: workers,
            source,
        })?;
    let zooms = (options.min_zoom, max_zoom);
    let mut stats = LevelStats::new(max_zoom, &pool);
    stream_levels(source, bounds, zooms, band_rows, &pool, &mut stats)?;
    // Quantized-mesh stores a tile's height range in f32, and its heights as steps of it.
    let widest = stats.widest.iter().fold(0.0f64, |w, &x| w.max(x));
    if !(stats.max_abs < f64::from(f32::MAX) / 2.0 && widest < f64::from(f32::MAX) / 2.0) {
        return Err(TerrainError::HeightsBeyondF32 {
            max_abs: stats.max_abs,
            widest,
        });
    }
    let mut writer = TileWriter::new(stats, out_dir, options, &pool, progress);
    stream_levels(source, bounds, zooms, band_rows, &pool, &mut writer)?;
    let mut levels = writer.finished;
    levels.reverse();
    Ok((levels, writer.available))
}

/// The first pass: what every tile of a level must agree on, from the whole level.
struct LevelStats<'p> {
    max_zoom: u8,
    /// The largest |height| of the finest level.
    max_abs: f64,
    /// Per level: the widest range of valid heights of any of its tiles.
    widest: Vec<f64>,
    /// Per level: seconds spent.
    seconds: Vec<f64>,
    pool: &'p rayon::ThreadPool,
}

impl<'p> LevelStats<'p> {
    fn new(max_zoom: u8, pool: &'p rayon::ThreadPool) -> Self {
        let levels = usize::from(max_zoom) + 1;
        LevelStats {
            max_zoom,
            max_abs: 0.0,
            widest: vec![0.0; levels],
            seconds: vec![0.0; levels],
            pool,
        }
    }
}

impl LevelSink for LevelStats<'_> {
    fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()> {
        let t = Instant::now();
        let tiles = tiles_of(level, tile_rows);
        let ranges: Vec<(f64, f64)> = self.pool.install(|| {
            tiles
                .par_iter()
                .filter_map(|&(x, y)| level.tile_height_range(x, y))
                .collect()
        });
        let z = usize::from(level.level);
        for (lo, hi) in ranges {
            self.widest[z] = self.widest[z].max(hi - lo);
            // Every sample of the finest level is in one of its tiles.
            if level.level == self.max_zoom {
                self.max_abs = self.max_abs.max(lo.abs()).max(hi.abs());
            }
        }
        self.seconds[z] += t.elapsed().as_secs_f64();
        Ok(())
    }

    fn level_done(&mut self, level: u8, seconds: f64) -> TerrainResult<()> {
        self.seconds[usize::from(level)] += seconds;
        Ok(())
    }
}

/// The tiles of tile rows `tile_rows` (local) of a level, in TMS row then column order.
fn tiles_of(level: &LevelRows, tile_rows: Range<u32>) -> Vec<(u32, u32)> {
    tile_rows
        .flat_map(|j| (0..level.tiles_x).map(move |i| (level.tx0 + i, level.ty0 + j)))
        .collect()
}

/// The level's bound and height quantum, from its widest tile and the finest level's
/// largest |height|.
fn level_budget(level: u8, widest: f64, quality: f64, max_abs: f64) -> LevelBudget {
    // The height quantum: the smallest power of two that fits every tile's range in
    // 32766 steps (so a minimum rounded down to the lattice still leaves room).
    let mut height_step = MIN_HEIGHT_STEP;
    while height_step * f64::from(QUANTIZED_MAX - 1) < widest {
        height_step *= 2.0;
    }
    let bound = quality * LEVEL_ZERO_ERROR / (1u64 << level) as f64;
    let half_step = height_step / 2.0;
    // The quantization error is at most half a step; keep a relative margin of 2^-30 for
    // the float arithmetic of interpolation.
    let margin = (bound + max_abs) / (1u64 << 30) as f64;
    LevelBudget {
        bound,
        step: height_step,
        max_edge: max_edge_length(level, bound),
        decimation: (bound - half_step - margin).max(0.0),
        verify: bound.max(half_step + margin),
        max_abs,
    }
}

/// The second pass: builds, checks and writes the tiles, row by row of each level.
struct TileWriter<'a> {
    out_dir: &'a Path,
    options: &'a TerrainOptions,
    pool: &'a rayon::ThreadPool,
    progress: &'a mut dyn FnMut(&LevelReport),
    budgets: Vec<LevelBudget>,
    /// Per level, while it is being written.
    reports: Vec<LevelReport>,
    /// Seconds of the first pass, per level.
    stats_seconds: Vec<f64>,
    available: Available,
    /// Finished levels, finest first.
    finished: Vec<LevelReport>,
}

impl<'a> TileWriter<'a> {
    fn new(
        stats: LevelStats<'_>,
        out_dir: &'a Path,
        options: &'a TerrainOptions,
        pool: &'a rayon::ThreadPool,
        progress: &'a mut dyn FnMut(&LevelReport),
    ) -> Self {
        let budgets: Vec<LevelBudget> = (0..=stats.max_zoom)
            .map(|z| {
                level_budget(
                    z,
                    stats.widest[usize::from(z)],
                    options.quality,
                    stats.max_abs,
                )
            })
            .collect();
        let reports = budgets
            .iter()
            .zip(0..)
            .map(|(budget, level)| LevelReport {
                level,
                bound: budget.bound,
                achieved_bound: budget.verify,
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
            out_dir,
            options,
            pool,
            progress,
            budgets,
            reports,
            stats_seconds: stats.seconds,
            available: vec![BTreeSet::new(); usize::from(stats.max_zoom) + 1],
            finished: Vec::new(),
        }
    }
}

impl LevelSink for TileWriter<'_> {
    fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()> {
        let t = Instant::now();
        let z = level.level;
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
        report.seconds += seconds + self.stats_seconds[z];
        (self.progress)(report);
        self.finished.push(report.clone());
        Ok(())
    }
}

impl TileWriter<'_> {
    /// Writes a tile of level `z` into the staging directory and counts it.
    fn write(&mut self, z: u8, tile: &TileOut) -> TerrainResult<()> {
        let dir = self.out_dir.join(z.to_string()).join(tile.x.to_string());
        if tinsmith_export::interrupted() {
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
        Ok(())
    }
}

fn write_atomic(path: &Path, bytes: &[u8]) -> TerrainResult<()> {
    let output = |source| TerrainError::Output {
        path: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut file = tinsmith_export::output_temp_file(dir).map_err(output)?;
    std::io::Write::write_all(&mut file, bytes).map_err(output)?;
    file.persist(path).map_err(|e| output(e.error))?;
    Ok(())
}

fn build_tile(
    raster: &LevelRows,
    x: u32,
    y: u32,
    budget: &LevelBudget,
    options: &TerrainOptions,
    metadata_available: Option<&Available>,
) -> TerrainResult<Option<TileOut>> {
    let z = raster.level;
    // Where the tile is written (`x` may be a turn east, see `tile_range`).
    let column = tile_column(z, x);
    let n = TILE_CELLS as usize;
    let (i0, j0) = raster.tile_origin(x, y);
    let values = raster.tile_values(x, y);
    let grid = Grid::new(TILE_CELLS + 1, TILE_CELLS + 1, values).expect("a 218 x 218 grid");
    if grid.valid_cell_count() == 0 {
        return Ok(None);
    }

    // Shared edges, each decided from the level raster alone: both neighbours agree.
    let limit = edge_limit(budget.decimation, budget.max_abs);
    let keep = |edge: EdgeProfile| {
        if limit > 0.0 {
            edge.simplify(limit, edge_span(budget.max_edge))
        } else {
            vec![true; n + 1]
        }
    };
    let south = keep(raster.edge(i0, j0, true));
    let north = keep(raster.edge(i0, j0 + n, true));
    let west = keep(raster.edge(i0, j0, false));
    let east = keep(raster.edge(i0 + n, j0, false));
    let last = TILE_CELLS;
    let keep_border = |gx: u32, gy: u32| {
        if gy == 0 {
            south[gx as usize]
        } else if gy == last {
            north[gx as usize]
        } else if gx == 0 {
            west[gy as usize]
        } else if gx == last {
            east[gy as usize]
        } else {
            true
        }
    };
    // Vertices at their samples: flat ground (the sea at 0, a tile the raster does not
    // reach) stays exactly at its height in the quantized tiles.
    let mut decimation_options =
        DecimationOptions::new(budget.decimation).with_vertex_heights(VertexHeights::Samples);
    decimation_options.max_abs_value = Some(budget.max_abs);
    decimation_options.max_edge_length = budget.max_edge;
    let tin = decimate_with_border(&grid, &decimation_options, &keep_border, &mut |_| {})
        .map_err(|source| TerrainError::Decimate {
            z,
            x: column,
            y,
            source,
        })?
        .tin;
    if tin.triangles().is_empty() {
        return Ok(None);
    }

    // Heights on the level's lattice: tile minimum rounded down to a multiple of the step.
    let s = budget.step;
    let (lo, hi) = tin
        .vertices()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.z), hi.max(v.z))
        });
    let k_min = (lo / s).floor();
    let min_height = k_min * s;
    let per_step = quanta_per_step(k_min, (hi / s).round() - k_min);
    let max_height = min_height + f64::from(QUANTIZED_MAX) * s / f64::from(per_step);
    let quantized: Vec<[u16; 3]> = tin
        .vertices()
        .iter()
        .map(|v| {
            let h = ((v.z / s).round() - k_min) * f64::from(per_step);
            [
                (v.x * U_PER_CELL) as u16,
                (v.y * U_PER_CELL) as u16,
                h.clamp(0.0, f64::from(QUANTIZED_MAX)) as u16,
            ]
        })
        .collect();

    // The promise, checked on what the decoder will compute.
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let decoded: Vec<f64> = quantized
        .iter()
        .map(|q| min_height + f64::from(q[2] / per_step as u16) * s)
        .collect();
    let check = tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &decoded, tin.triangles()),
        &VerifyOptions::new().with_max_error(budget.verify),
    )
    .map_err(|e| TerrainError::Verify {
        z,
        x: column,
        y,
        problems: e.to_string(),
    })?;
    if !check.passed() {
        return Err(TerrainError::Verify {
            z,
            x: column,
            y,
            problems: check.problems.join("; "),
        });
    }

    let rect = tile_rectangle(z, x, y);
    let normals: Option<Vec<[f64; 3]>> = options.normals.then(|| {
        let d = step(z);
        tin.vertices()
            .iter()
            .map(|v| {
                let (gi, gj) = (i0 + v.x as usize, j0 + v.y as usize);
                raster.normal(
                    gi,
                    gj,
                    rect.west + f64::from(v.x) * d,
                    rect.south + f64::from(v.y) * d,
                )
            })
            .collect()
    });
    let metadata = metadata_available.map(|available| metadata_json(available, z, column, y));
    let mut tile = QuantizedMeshTile::new(
        rect,
        min_height as f32,
        max_height as f32,
        &quantized,
        tin.triangles(),
    );
    if let Some(normals) = &normals {
        tile = tile.with_normals(normals);
    }
    if let Some(metadata) = &metadata {
        tile = tile.with_metadata(metadata);
    }
    let mut bytes = tile.encode().map_err(|source| TerrainError::Encode {
        z,
        x: column,
        y,
        source,
    })?;
    if options.gzip {
        bytes = gzip(&bytes);
    }
    Ok(Some(TileOut {
        x: column,
        y,
        bytes,
        vertices: quantized.len(),
        triangles: tin.triangles().len(),
        max_error: check.max_error,
    }))
}

/// `available` tiles of one level as `{startX, startY, endX, endY}` rectangles (runs of
/// columns along each row, merged with identical runs of the rows above), restricted to
/// columns `x_range` and rows `y_range`.
fn rectangles(tiles: &BTreeSet<(u32, u32)>, x_range: [u32; 2], y_range: [u32; 2]) -> Vec<[u32; 4]> {
    let mut by_row: std::collections::BTreeMap<u32, Vec<[u32; 2]>> = Default::default();
    for &(x, y) in tiles {
        if x < x_range[0] || x > x_range[1] || y < y_range[0] || y > y_range[1] {
            continue;
        }
        let runs = by_row.entry(y).or_default();
        match runs.last_mut() {
            Some(run) if run[1] + 1 == x => run[1] = x,
            _ => runs.push([x, x]),
        }
    }
    // The set is ordered by x first, so each row's columns arrive in increasing order.
    let mut out: Vec<[u32; 4]> = Vec::new();
    let mut open: Vec<[u32; 4]> = Vec::new();
    for (&y, runs) in &by_row {
        let mut next_open = Vec::new();
        for run in runs {
            match open
                .iter()
                .position(|r| r[0] == run[0] && r[2] == run[1] && r[3] + 1 == y)
            {
                Some(k) => {
                    let mut r = open.swap_remove(k);
                    r[3] = y;
                    next_open.push(r);
                }
                None => next_open.push([run[0], y, run[1], y]),
            }
        }
        out.append(&mut open);
        open = next_open;
    }
    out.append(&mut open);
    out.sort_by_key(|r| (r[1], r[0]));
    out
}

fn rectangles_json(rects: &[[u32; 4]]) -> String {
    let mut s = String::from("[");
    for (k, r) in rects.iter().enumerate() {
        if k > 0 {
            s.push(',');
        }
        let _ = write!(
            s,
            r#"{{"startX":{},"startY":{},"endX":{},"endY":{}}}"#,
            r[0], r[1], r[2], r[3]
        );
    }
    s.push(']');
    s
}

/// The metadata extension of tile z/x/y: availability of levels z+1 ..= z+10 below it.
fn metadata_json(available: &Available, z: u8, x: u32, y: u32) -> String {
    let mut levels = Vec::new();
    for k in 1..=u32::from(METADATA_AVAILABILITY) {
        let level = usize::from(z) + k as usize;
        let Some(tiles) = available.get(level) else {
            break;
        };
        let f = 1u32 << k;
        let rects = rectangles(tiles, [x * f, (x + 1) * f - 1], [y * f, (y + 1) * f - 1]);
        levels.push(rectangles_json(&rects));
    }
    // Trailing empty levels say nothing; CesiumJS needs no entry for them.
    while levels.last().is_some_and(|l| l == "[]") {
        levels.pop();
    }
    format!(r#"{{"available":[{}]}}"#, levels.join(","))
}

fn write_layer_json(
    input: &Path,
    out_dir: &Path,
    options: &TerrainOptions,
    bounds: &GeoBounds,
    max_zoom: u8,
    available: &Available,
) -> TerrainResult<()> {
    let name = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "terrain".into());
    let mut extensions = Vec::new();
    if options.normals {
        extensions.push(serde_json::json!("octvertexnormals"));
    }
    if options.metadata {
        extensions.push(serde_json::json!("metadata"));
    }
    let all = [0, u32::MAX];
    // The deepest level that has tiles (a tiny raster's finest levels may have none).
    let max_zoom = available
        .iter()
        .rposition(|tiles| !tiles.is_empty())
        .map_or(max_zoom, |z| z as u8);
    let available: Vec<serde_json::Value> = available[..=usize::from(max_zoom)]
        .iter()
        .map(|tiles| {
            rectangles(tiles, all, all)
                .iter()
                .map(|r| {
                    serde_json::json!({"startX": r[0], "startY": r[1], "endX": r[2], "endY": r[3]})
                })
                .collect()
        })
        .collect();
    let mut layer = serde_json::json!({
        "tilejson": "2.1.0",
        "name": name,
        "description": "made by tinsmith",
        "version": "1.0.0",
        "format": "quantized-mesh-1.0",
        "scheme": "tms",
        "projection": "EPSG:4326",
        "tiles": ["{z}/{x}/{y}.terrain?v={version}"],
        "minzoom": options.min_zoom,
        "maxzoom": max_zoom,
        "bounds": bounds_array(bounds),
        "extensions": extensions,
        "available": available,
        "attribution": "",
    });
    if options.metadata {
        layer["metadataAvailability"] = serde_json::json!(METADATA_AVAILABILITY);
    }
    let text = serde_json::to_string_pretty(&layer).expect("JSON values serialize");
    write_atomic(&out_dir.join("layer.json"), text.as_bytes())
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
        let source = stream::Hills {
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
                band_rows,
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
