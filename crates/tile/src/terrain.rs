//! A Cesium quantized-mesh terrain pyramid: geographic TMS tiles (EPSG:4326, 2x1 root
//! tiles, y = 0 in the south), each decimated within `quality x e(level)`, with shared
//! edges simplified once so that same-level neighbours keep identical edge vertices.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use tinsmith_core::{decimate_with_border, DecimationOptions, Grid};
use tinsmith_export::{gzip, surface_normal, GeoRectangle, QuantizedMeshTile, QUANTIZED_MAX};
use tinsmith_raster::{geographic_bounds, warp_to_geographic, GeoBounds, GeoLattice};
use tinsmith_verify::{GridRef, MeshRef, VerifyOptions};

use crate::edge::{edge_limit, edge_span, EdgeProfile};

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
        }
    }
}

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
    /// Bytes written (as stored, gzipped or not).
    pub bytes: u64,
    /// Vertices over all tiles.
    pub vertices: u64,
    /// Triangles over all tiles.
    pub triangles: u64,
    /// Seconds spent on the level (including the warp or downsampling that made it).
    pub seconds: f64,
}

/// What [`build_terrain`] produced.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TerrainReport {
    /// The input's extent in EPSG:4326.
    pub bounds: [f64; 4],
    /// Coarsest level.
    pub min_zoom: u8,
    /// Finest level.
    pub max_zoom: u8,
    /// Per level, coarsest first.
    pub levels: Vec<LevelReport>,
}

/// The samples of one level on its lattice, over whole tiles: global lattice column
/// `x0 + i`, row `y0 + j` (row 0 the southernmost), NaN where there is no data.
struct LevelRaster {
    level: u8,
    /// First tile column and TMS row covered.
    tx0: u32,
    ty0: u32,
    /// Tiles covered.
    tiles_x: u32,
    tiles_y: u32,
    width: usize,
    height: usize,
    values: Vec<f32>,
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

/// The tile rectangle `z/x/y` (TMS y) in degrees.
pub fn tile_rectangle(z: u8, x: u32, y: u32) -> GeoRectangle {
    let size = 180.0 / (1u64 << z) as f64;
    GeoRectangle {
        west: -180.0 + f64::from(x) * size,
        south: -90.0 + f64::from(y) * size,
        east: -180.0 + f64::from(x + 1) * size,
        north: -90.0 + f64::from(y + 1) * size,
    }
}

/// The tiles of `level` that the bounds touch: columns and rows, inclusive.
fn tile_range(bounds: &GeoBounds, level: u8) -> ([u32; 2], [u32; 2]) {
    let n = 1u64 << level;
    let size = 180.0 / n as f64;
    let clamp = |v: f64, max: u64| (v.floor().max(0.0) as u64).min(max - 1) as u32;
    let x = [
        clamp((bounds.west + 180.0) / size, 2 * n),
        clamp((bounds.east + 180.0) / size, 2 * n),
    ];
    let y = [
        clamp((bounds.south + 90.0) / size, n),
        clamp((bounds.north + 90.0) / size, n),
    ];
    (x, y)
}

impl LevelRaster {
    fn empty(bounds: &GeoBounds, level: u8) -> LevelRaster {
        let ([x0, x1], [y0, y1]) = tile_range(bounds, level);
        let (tiles_x, tiles_y) = (x1 - x0 + 1, y1 - y0 + 1);
        let width = (tiles_x * TILE_CELLS + 1) as usize;
        let height = (tiles_y * TILE_CELLS + 1) as usize;
        LevelRaster {
            level,
            tx0: x0,
            ty0: y0,
            tiles_x,
            tiles_y,
            width,
            height,
            values: vec![f32::NAN; width * height],
        }
    }

    /// The finest level, warped from the input by GDAL.
    fn warped(path: &Path, band: usize, bounds: &GeoBounds, level: u8) -> TerrainResult<Self> {
        let mut raster = LevelRaster::empty(bounds, level);
        let d = step(level);
        let lattice = GeoLattice {
            west: -180.0 + f64::from(raster.tx0 * TILE_CELLS) * d,
            south: -90.0 + f64::from(raster.ty0 * TILE_CELLS) * d,
            step: d,
            width: raster.width as u32,
            height: raster.height as u32,
        };
        raster.values = warp_to_geographic(path, band, &lattice)?;
        Ok(raster)
    }

    /// The next coarser level: lattice point (X, Y) is the finer level's (2X, 2Y),
    /// low-pass filtered with the binomial [1 4 6 4 1] x [1 4 6 4 1] kernel over the valid
    /// finer samples; nodata only where all 25 are. The domain so grows by at most one
    /// coarse sample per level, which keeps small inputs visible at coarse levels.
    fn coarser(&self, bounds: &GeoBounds) -> LevelRaster {
        let mut out = LevelRaster::empty(bounds, self.level - 1);
        let fx0 = i64::from(self.tx0 * TILE_CELLS);
        let fy0 = i64::from(self.ty0 * TILE_CELLS);
        let cx0 = i64::from(out.tx0 * TILE_CELLS);
        let cy0 = i64::from(out.ty0 * TILE_CELLS);
        let fine = |gx: i64, gy: i64| -> f32 {
            let (i, j) = (gx - fx0, gy - fy0);
            if i < 0 || j < 0 || i >= self.width as i64 || j >= self.height as i64 {
                f32::NAN
            } else {
                self.values[j as usize * self.width + i as usize]
            }
        };
        const TAPS: [(i64, f64); 5] = [(-2, 1.0), (-1, 4.0), (0, 6.0), (1, 4.0), (2, 1.0)];
        let width = out.width;
        out.values
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(j, row)| {
                let gy = 2 * (cy0 + j as i64);
                for (i, slot) in row.iter_mut().enumerate() {
                    let gx = 2 * (cx0 + i as i64);
                    let (mut sum, mut weight) = (0.0f64, 0.0f64);
                    for (dy, wy) in TAPS {
                        for (dx, wx) in TAPS {
                            let v = fine(gx + dx, gy + dy);
                            if v.is_finite() {
                                sum += wx * wy * f64::from(v);
                                weight += wx * wy;
                            }
                        }
                    }
                    if weight == 0.0 {
                        continue;
                    }
                    *slot = (sum / weight) as f32;
                }
            });
        out
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        f64::from(self.values[j * self.width + i])
    }

    /// Whether the cell with lower-left sample (i, j) lies in the raster and has four
    /// valid corners.
    fn cell_valid(&self, i: i64, j: i64) -> bool {
        if i < 0 || j < 0 || i + 1 >= self.width as i64 || j + 1 >= self.height as i64 {
            return false;
        }
        let (i, j) = (i as usize, j as usize);
        [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
            .iter()
            .all(|&(a, b)| self.at(a, b).is_finite())
    }

    /// The edge from sample (i, j) along +x (`horizontal`) or +y, `TILE_CELLS` steps,
    /// as both tiles beside it see it.
    fn edge(&self, i: usize, j: usize, horizontal: bool) -> EdgeProfile {
        let n = TILE_CELLS as usize;
        let (i, j) = (i as i64, j as i64);
        let point = |k: i64| if horizontal { (i + k, j) } else { (i, j + k) };
        let values = (0..=n as i64)
            .map(|k| {
                let (a, b) = point(k);
                self.at(a as usize, b as usize)
            })
            .collect();
        let open = (0..n as i64)
            .map(|k| {
                let (a, b) = point(k);
                // The cells on both sides of the step; a side outside the raster is the
                // raster's outer border, where no tile has data.
                let (side1, side2) = if horizontal {
                    ((a, b - 1), (a, b))
                } else {
                    ((a - 1, b), (a, b))
                };
                let inside = |(x, y): (i64, i64)| {
                    x >= 0 && y >= 0 && x + 1 < self.width as i64 && y + 1 < self.height as i64
                };
                [side1, side2]
                    .iter()
                    .all(|&c| !inside(c) || self.cell_valid(c.0, c.1))
            })
            .collect();
        EdgeProfile::new(values, open)
    }

    /// Unit ECEF normal at sample (i, j) from central differences of the level's samples
    /// (one-sided at nodata or the raster's edge): the same for every tile that has the
    /// sample, so normals are continuous across tile edges.
    fn normal(&self, i: usize, j: usize, lon: f64, lat: f64) -> [f64; 3] {
        let d = step(self.level).to_radians();
        let z = self.at(i, j);
        let sample = |a: i64, b: i64| -> Option<f64> {
            if a < 0 || b < 0 || a >= self.width as i64 || b >= self.height as i64 {
                return None;
            }
            Some(self.at(a as usize, b as usize)).filter(|v| v.is_finite())
        };
        let slope = |lo: Option<f64>, hi: Option<f64>, spacing: f64| match (lo, hi) {
            (Some(a), Some(b)) => (b - a) / (2.0 * spacing),
            (None, Some(b)) => (b - z) / spacing,
            (Some(a), None) => (z - a) / spacing,
            (None, None) => 0.0,
        };
        let (ii, jj) = (i as i64, j as i64);
        let dx = tinsmith_export::WGS84_A * d * lat.to_radians().cos().max(1e-6);
        let dy = tinsmith_export::WGS84_A * d;
        let ge = slope(sample(ii - 1, jj), sample(ii + 1, jj), dx);
        let gn = slope(sample(ii, jj - 1), sample(ii, jj + 1), dy);
        let (e, n, u) = (-ge, -gn, 1.0);
        let len = (e * e + n * n + u * u).sqrt();
        let (e, n, u) = (e / len, n / len, u / len);
        let (lon, lat) = (lon.to_radians(), lat.to_radians());
        let east = [-lon.sin(), lon.cos(), 0.0];
        let north = [-lat.sin() * lon.cos(), -lat.sin() * lon.sin(), lat.cos()];
        let up = surface_normal(lon.to_degrees(), lat.to_degrees());
        [0, 1, 2].map(|k| e * east[k] + n * north[k] + u * up[k])
    }
}

/// The level's bound and its height quantum.
#[derive(Debug, Clone, Copy)]
struct LevelBudget {
    step: f64,
    /// Longest edge, in lattice spacings (see [`max_edge_length`]).
    max_edge: Option<u32>,
    /// What decimation may use: the bound less the quantization error (half a step).
    decimation: f64,
    verify: f64,
    max_abs: f64,
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
///
/// The finest level is warped once from the input with GDAL (bilinear); each coarser level
/// is the finer one smoothed and halved, so the input is read once.
pub fn build_terrain(
    input: &Path,
    out_dir: &Path,
    options: &TerrainOptions,
    progress: &mut dyn FnMut(&LevelReport),
) -> TerrainResult<TerrainReport> {
    if !(options.quality > 0.0 && options.quality.is_finite()) {
        return Err(TerrainError::Options(format!(
            "--quality must be a positive number, got {}",
            options.quality
        )));
    }
    let bounds = geographic_bounds(input, options.band)?;
    let max_zoom = match options.max_zoom {
        Some(z) => z,
        None => (0..MAX_LEVEL)
            .find(|&l| step(l) <= bounds.resolution * (1.0 + 1e-9))
            .unwrap_or(MAX_LEVEL),
    };
    if max_zoom > MAX_LEVEL || options.min_zoom > max_zoom {
        return Err(TerrainError::Options(format!(
            "zoom range {}..={max_zoom} is not within 0..={MAX_LEVEL}",
            options.min_zoom
        )));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads)
        .build()
        .map_err(|source| TerrainError::Threads {
            threads: options.threads,
            source,
        })?;
    std::fs::create_dir_all(out_dir).map_err(|source| TerrainError::Output {
        path: out_dir.to_path_buf(),
        source,
    })?;

    let mut available: Available = vec![BTreeSet::new(); usize::from(max_zoom) + 1];
    let mut levels = Vec::new();
    let mut t = Instant::now();
    let mut raster = LevelRaster::warped(input, options.band, &bounds, max_zoom)?;
    // One rounding slack for every level, from the finest raster's largest |height|.
    let max_abs = raster
        .values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, &v| m.max(f64::from(v).abs()));
    loop {
        let level = raster.level;
        let mut report =
            pool.install(|| build_level(&raster, out_dir, options, max_abs, &mut available))?;
        report.seconds = t.elapsed().as_secs_f64();
        progress(&report);
        levels.push(report);
        if level == options.min_zoom {
            break;
        }
        t = Instant::now();
        raster = pool.install(|| raster.coarser(&bounds));
    }
    levels.reverse();
    write_layer_json(input, out_dir, options, &bounds, max_zoom, &available)?;
    Ok(TerrainReport {
        bounds: [bounds.west, bounds.south, bounds.east, bounds.north],
        min_zoom: options.min_zoom,
        max_zoom,
        levels,
    })
}

/// The tiles of one level, in TMS row then column order.
fn level_tiles(raster: &LevelRaster) -> Vec<(u32, u32)> {
    (0..raster.tiles_y)
        .flat_map(|j| (0..raster.tiles_x).map(move |i| (raster.tx0 + i, raster.ty0 + j)))
        .collect()
}

/// The range of valid heights of tile (x, y), if it has any.
fn tile_height_range(raster: &LevelRaster, x: u32, y: u32) -> Option<(f64, f64)> {
    let n = TILE_CELLS as usize;
    let i0 = ((x - raster.tx0) * TILE_CELLS) as usize;
    let j0 = ((y - raster.ty0) * TILE_CELLS) as usize;
    let mut range: Option<(f64, f64)> = None;
    for j in j0..=j0 + n {
        for v in &raster.values[j * raster.width + i0..=j * raster.width + i0 + n] {
            if v.is_finite() {
                let v = f64::from(*v);
                range = Some(match range {
                    Some((lo, hi)) => (lo.min(v), hi.max(v)),
                    None => (v, v),
                });
            }
        }
    }
    range
}

fn build_level(
    raster: &LevelRaster,
    out_dir: &Path,
    options: &TerrainOptions,
    max_abs: f64,
    available: &mut Available,
) -> TerrainResult<LevelReport> {
    let level = raster.level;
    let tiles = level_tiles(raster);
    // The height quantum: the smallest power of two that fits every tile's range in
    // 32766 steps (so a minimum rounded down to the lattice still leaves room).
    let widest = tiles
        .par_iter()
        .filter_map(|&(x, y)| tile_height_range(raster, x, y))
        .map(|(lo, hi)| hi - lo)
        .reduce(|| 0.0, f64::max);
    let mut height_step = MIN_HEIGHT_STEP;
    while height_step * f64::from(QUANTIZED_MAX - 1) < widest {
        height_step *= 2.0;
    }
    let bound = options.quality * LEVEL_ZERO_ERROR / (1u64 << level) as f64;
    let half_step = height_step / 2.0;
    // The quantization error is at most half a step; keep a relative margin of 2^-30 for
    // the float arithmetic of interpolation.
    let margin = (bound + max_abs) / (1u64 << 30) as f64;
    let budget = LevelBudget {
        step: height_step,
        max_edge: max_edge_length(level, bound),
        decimation: (bound - half_step - margin).max(0.0),
        verify: bound.max(half_step + margin),
        max_abs,
    };

    let metadata_available = if options.metadata && level.is_multiple_of(METADATA_AVAILABILITY) {
        Some(&*available)
    } else {
        None
    };
    let results: Vec<TerrainResult<Option<TileOut>>> = tiles
        .par_iter()
        .map(|&(x, y)| build_tile(raster, x, y, &budget, options, metadata_available))
        .collect();

    let mut report = LevelReport {
        level,
        bound,
        achieved_bound: budget.verify,
        height_step,
        measured_max_error: 0.0,
        tiles: 0,
        empty_tiles: 0,
        bytes: 0,
        vertices: 0,
        triangles: 0,
        seconds: 0.0,
    };
    for result in results {
        let Some(tile) = result? else {
            report.empty_tiles += 1;
            continue;
        };
        let dir = out_dir.join(level.to_string()).join(tile.x.to_string());
        std::fs::create_dir_all(&dir).map_err(|source| TerrainError::Output {
            path: dir.clone(),
            source,
        })?;
        write_atomic(&dir.join(format!("{}.terrain", tile.y)), &tile.bytes)?;
        available[usize::from(level)].insert((tile.x, tile.y));
        report.tiles += 1;
        report.bytes += tile.bytes.len() as u64;
        report.vertices += tile.vertices as u64;
        report.triangles += tile.triangles as u64;
        report.measured_max_error = report.measured_max_error.max(tile.max_error);
    }
    Ok(report)
}

fn write_atomic(path: &Path, bytes: &[u8]) -> TerrainResult<()> {
    let output = |source| TerrainError::Output {
        path: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut file = tempfile::NamedTempFile::new_in(dir).map_err(output)?;
    std::io::Write::write_all(&mut file, bytes).map_err(output)?;
    file.persist(path).map_err(|e| output(e.error))?;
    Ok(())
}

fn build_tile(
    raster: &LevelRaster,
    x: u32,
    y: u32,
    budget: &LevelBudget,
    options: &TerrainOptions,
    metadata_available: Option<&Available>,
) -> TerrainResult<Option<TileOut>> {
    let z = raster.level;
    let n = TILE_CELLS as usize;
    let i0 = ((x - raster.tx0) * TILE_CELLS) as usize;
    let j0 = ((y - raster.ty0) * TILE_CELLS) as usize;
    let mut values = Vec::with_capacity((n + 1) * (n + 1));
    for j in j0..=j0 + n {
        values.extend(
            raster.values[j * raster.width + i0..=j * raster.width + i0 + n]
                .iter()
                .map(|&v| f64::from(v)),
        );
    }
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
    let mut decimation_options = DecimationOptions::new(budget.decimation);
    decimation_options.max_abs_value = Some(budget.max_abs);
    decimation_options.max_edge_length = budget.max_edge;
    let tin = decimate_with_border(&grid, &decimation_options, &keep_border, &mut |_| {})
        .map_err(|source| TerrainError::Decimate { z, x, y, source })?
        .tin;
    if tin.triangles().is_empty() {
        return Ok(None);
    }

    // Heights on the level's lattice: tile minimum rounded down to a multiple of the step.
    let s = budget.step;
    let lo = tin
        .vertices()
        .iter()
        .map(|v| v.z)
        .fold(f64::INFINITY, f64::min);
    let k_min = (lo / s).floor();
    let min_height = k_min * s;
    let max_height = (k_min + f64::from(QUANTIZED_MAX)) * s;
    let quantized: Vec<[u16; 3]> = tin
        .vertices()
        .iter()
        .map(|v| {
            let h = (v.z / s).round() - k_min;
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
        .map(|q| min_height + f64::from(q[2]) * s)
        .collect();
    let check = tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &decoded, tin.triangles()),
        &VerifyOptions::new().with_max_error(budget.verify),
    )
    .map_err(|e| TerrainError::Verify {
        z,
        x,
        y,
        problems: e.to_string(),
    })?;
    if !check.passed() {
        return Err(TerrainError::Verify {
            z,
            x,
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
    let metadata = metadata_available.map(|available| metadata_json(available, z, x, y));
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
    let mut bytes = tile
        .encode()
        .map_err(|source| TerrainError::Encode { z, x, y, source })?;
    if options.gzip {
        bytes = gzip(&bytes);
    }
    Ok(Some(TileOut {
        x,
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
    let available: Vec<serde_json::Value> = available
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
        "bounds": [bounds.west, bounds.south, bounds.east, bounds.north],
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
