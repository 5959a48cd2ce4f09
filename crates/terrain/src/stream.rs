//! The pyramid as a stream of rows: the finest level warped band by band, each coarser level
//! filtered from the finer one's rows as soon as they exist, each level's tile rows handed
//! out as soon as every row they read is held, and rows nobody needs any more dropped, so
//! memory is a few bands of tile rows per level, whatever the raster's height.

use std::ops::Range;
use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use tinsmith_raster::sample_geographic;

use crate::rows::LevelRows;
use crate::tms::TileRect;
use crate::TerrainResult;

/// Where the finest level's samples come from.
pub(super) trait RowSource: Sync {
    /// Rows `rows`, columns `columns` of `level`'s lattice (local indices), row-major, row
    /// 0 the southernmost, NaN where there is no data. A sample must be the same whatever
    /// rows and columns are asked with it.
    fn rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>>;
}

/// Rows `rows` of `level`, all columns, from `source` where they are in the level's reach
/// ([`LevelRows::within`]), NaN elsewhere.
fn sample_reach(
    source: &dyn RowSource,
    level: &LevelRows,
    rows: Range<usize>,
) -> TerrainResult<Vec<f32>> {
    let Some(reach) = level.reach() else {
        return source.rows(level, rows, 0..level.width);
    };
    let width = level.width;
    let mut out = vec![f32::NAN; width * rows.len()];
    let inner = rows.start.max(reach.rows.start)..rows.end.min(reach.rows.end);
    if inner.is_empty() {
        return Ok(out);
    }
    for columns in reach.column_runs() {
        let values = source.rows(level, inner.clone(), columns.clone())?;
        for (k, row) in values.chunks_exact(columns.len()).enumerate() {
            let start = (inner.start - rows.start + k) * width + columns.start;
            out[start..start + columns.len()].copy_from_slice(row);
        }
    }
    Ok(out)
}

/// A band of the input, sampled at the level's lattice points ([`sample_geographic`]):
/// each sample depends only on the input and its position, so a row gets the same
/// samples in any band, and a band is sampled in one call.
pub(super) struct Warp<'a> {
    pub(super) path: &'a Path,
    pub(super) band: usize,
    /// What the band's heights are above; they are turned into ellipsoidal heights.
    pub(super) datum: &'a tinsmith_raster::VerticalDatum,
    /// The height of points outside the raster (NaN: no data there).
    pub(super) outside: f32,
}

impl RowSource for Warp<'_> {
    fn rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>> {
        let lattice = level.lattice(rows, columns);
        Ok(sample_geographic(
            self.path,
            self.band,
            &lattice,
            self.datum,
            self.outside,
        )?)
    }
}

/// What the stream hands its rows to.
pub(super) trait LevelSink {
    /// Tile rows `tile_rows` (local, 0 the level's southernmost) of `level`: every
    /// lattice row they read (their own and one beyond each side, see [`LevelRows`]) is
    /// held. Called once per tile row, in increasing order within a level.
    fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()>;

    /// Every tile row of `level` has been handed out; `seconds` were spent making its rows.
    fn level_done(&mut self, level: u8, seconds: f64) -> TerrainResult<()>;
}

/// Samples per warp band of the finest level (16 MiB of f32). Bands are whole tile rows,
/// at least one; a level that fits comes in one band, as one warp.
const BAND_SAMPLES: usize = 1 << 22;

/// Tile rows per warp band of a level over `rect`.
pub(super) fn band_tile_rows(rect: TileRect) -> u32 {
    let width = LevelRows::new(rect).width;
    let rows = BAND_SAMPLES / (width * rect.tiling.cells as usize);
    rows.clamp(1, u32::MAX as usize) as u32
}

/// The finest level's warp bands: `band_tile_rows` tile rows each, the first with the
/// halo row above, so that each band completes its tile rows.
fn bands(level: &LevelRows, band_tile_rows: u32) -> Vec<Range<usize>> {
    let rows = band_tile_rows.max(1) as usize * level.tiling.cells as usize;
    let mut out = Vec::new();
    let mut start = 0;
    while start < level.height {
        let end = (out.len() * rows + rows + 2).min(level.height);
        out.push(start..end);
        start = end;
    }
    out
}

/// One level's place in the stream.
struct Level {
    rows: LevelRows,
    /// The next tile row (local) to hand out.
    next_tile_row: u32,
    /// Seconds spent making the level's rows.
    seconds: f64,
    done: bool,
}

/// Streams levels `max_zoom` down to `min_zoom`, each the lattice `level_of(level)` (its
/// tiles and reach), from `source` into `sink`. Each level's rectangle must cover the next
/// coarser one's samples' sources wherever they matter (the coarser level reads the finer
/// samples around twice its own indices; outside the finer rectangle it reads nodata).
///
/// The finest level is read in bands of `band_tile_rows` tile rows, a group of one band per
/// thread at a time, in parallel; the next group is warped while this group's rows go
/// through the levels. After each band, from the finest level down, each
/// level hands its complete tile rows to the sink, then makes every coarser row its rows
/// allow, then drops the rows neither its tiles nor the coarser level need any more.
///
/// # Guarantees
/// - Every level's rows equal those of the whole level made at once (the warp of the
///   whole lattice, then [`LevelRows::coarser_rows`] of the whole finer level), for any
///   band height, given a source whose samples do not depend on the band.
/// - Tile rows reach the sink in a fixed order that depends on the levels and the band
///   height only, never on the threads; levels finish finest first.
/// - When a tile row of level z reaches the sink, every tile row of every finer level
///   inside its footprint has already reached it: a coarser row needs finer rows beyond
///   the footprint's tile rows, and a level hands out its tile rows before making coarser
///   rows.
/// - Held rows per level: at most a band plus one tile row and a few halo rows; besides,
///   two groups of warped bands.
///
/// # Errors
/// The first error of the source or the sink; the stream stops there.
pub(super) fn stream_levels(
    source: &dyn RowSource,
    level_of: &dyn Fn(u8) -> LevelRows,
    zooms: (u8, u8),
    band_tile_rows: u32,
    pool: &rayon::ThreadPool,
    sink: &mut dyn LevelSink,
) -> TerrainResult<()> {
    let (min_zoom, max_zoom) = zooms;
    let mut levels: Vec<Level> = (min_zoom..=max_zoom)
        .rev()
        .map(|z| Level {
            rows: level_of(z),
            next_tile_row: 0,
            seconds: 0.0,
            done: false,
        })
        .collect();
    let bands = bands(&levels[0].rows, band_tile_rows);
    let groups: Vec<&[Range<usize>]> = bands.chunks(pool.current_num_threads().max(1)).collect();
    // The finest level's geometry, for the warps running beside the tiles.
    let finest = level_of(max_zoom);
    let warp = |group: &[Range<usize>]| -> (Vec<TerrainResult<Vec<f32>>>, f64) {
        let t = Instant::now();
        let warped = pool.install(|| {
            group
                .par_iter()
                .map(|rows| sample_reach(source, &finest, rows.clone()))
                .collect()
        });
        (warped, t.elapsed().as_secs_f64())
    };
    // The next group is warped on its own thread while this one's tiles are built; the
    // samples do not depend on the timing.
    std::thread::scope(|scope| -> TerrainResult<()> {
        let mut next = groups
            .first()
            .map(|&group| scope.spawn(move || warp(group)));
        for k in 0..groups.len() {
            let (warped, seconds) = next
                .take()
                .expect("a warp per group")
                .join()
                .expect("the warp thread does not panic");
            next = groups
                .get(k + 1)
                .map(|&group| scope.spawn(move || warp(group)));
            levels[0].seconds += seconds;
            for samples in warped {
                levels[0].rows.push(&samples?);
                cascade(&mut levels, pool, sink)?;
            }
        }
        Ok(())
    })?;
    for level in &levels {
        assert!(
            level.done,
            "level {} unfinished: rows to {}, tile rows to {}",
            level.rows.level,
            level.rows.end(),
            level.next_tile_row
        );
    }
    Ok(())
}

/// From the finest level down: hand out the complete tile rows, make the coarser rows that
/// can be made, drop the rows no longer needed.
fn cascade(
    levels: &mut [Level],
    pool: &rayon::ThreadPool,
    sink: &mut dyn LevelSink,
) -> TerrainResult<()> {
    for k in 0..levels.len() {
        let (finer, coarser) = levels.split_at_mut(k + 1);
        let level = &mut finer[k];
        let ready = level.rows.ready_tile_rows();
        if ready > level.next_tile_row {
            sink.tile_rows(&level.rows, level.next_tile_row..ready)?;
            level.next_tile_row = ready;
        }
        if !level.done && level.next_tile_row == level.rows.tiles_y {
            level.done = true;
            sink.level_done(level.rows.level, level.seconds)?;
        }
        let mut keep = level.rows.first_row_of_tile_row(level.next_tile_row);
        if let Some(coarse) = coarser.first_mut() {
            let t = Instant::now();
            let rows = coarse.rows.end()..level.rows.coarser_rows_ready(&coarse.rows);
            if !rows.is_empty() {
                let values = pool.install(|| level.rows.coarser_rows(&coarse.rows, rows));
                coarse.rows.push(&values);
            }
            coarse.seconds += t.elapsed().as_secs_f64();
            keep = keep.min(level.rows.first_row_for(&coarse.rows));
        }
        level.rows.drop_below(keep);
    }
    Ok(())
}

/// A made-up finest level for tests: smooth hills with a nodata disc, each sample a
/// function of its global lattice indices only (so any band gives the same samples).
#[cfg(test)]
pub(super) struct Hills {
    /// Centre (lon, lat) and radius of the nodata disc, degrees.
    pub(super) hole: [f64; 3],
}

#[cfg(test)]
impl RowSource for Hills {
    fn rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>> {
        let lattice = level.lattice(rows, columns);
        let mut out = Vec::with_capacity(lattice.width as usize * lattice.height as usize);
        for j in 0..lattice.height {
            let lat = lattice.lat(j);
            for i in 0..lattice.width {
                let lon = lattice.lon(i);
                let [cx, cy, r] = self.hole;
                let v = if (lon - cx).hypot(lat - cy) < r {
                    f32::NAN
                } else {
                    (300.0 * (lon * 40.0).sin() * (lat * 27.0).cos() + 80.0 * (lon * 200.0).cos())
                        as f32
                };
                out.push(v);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tms::{Scheme, Tiling, LATTICE_CELLS};
    use tinsmith_raster::GeoBounds;

    /// The next coarser level of a whole finer level, as the pipeline made it before it
    /// streamed: a reference that shares no code with [`LevelRows::coarser_rows`].
    fn whole_coarser(fine: &LevelRows, fine_values: &[f32], coarse: &LevelRows) -> Vec<f32> {
        let c = i64::from(fine.tiling.cells);
        let (fx0, fy0) = (i64::from(fine.tx0) * c, i64::from(fine.ty0) * c);
        let (cx0, cy0) = (i64::from(coarse.tx0) * c, i64::from(coarse.ty0) * c);
        let at = |gx: i64, gy: i64| -> f32 {
            let (i, j) = (gx - fx0, gy - fy0);
            if i < 0 || j < 0 || i >= fine.width as i64 || j >= fine.height as i64 {
                f32::NAN
            } else {
                fine_values[j as usize * fine.width + i as usize]
            }
        };
        let taps = [(-2, 1.0), (-1, 4.0), (0, 6.0), (1, 4.0), (2, 1.0)];
        let mut out = vec![f32::NAN; coarse.width * coarse.height];
        for j in 0..coarse.height {
            for i in 0..coarse.width {
                let (gx, gy) = (2 * (cx0 + i as i64), 2 * (cy0 + j as i64));
                let (mut sum, mut weight) = (0.0f64, 0.0f64);
                for (dy, wy) in taps {
                    for (dx, wx) in taps {
                        let v = at(gx + dx, gy + dy);
                        if v.is_finite() {
                            sum += wx * wy * f64::from(v);
                            weight += wx * wy;
                        }
                    }
                }
                if weight > 0.0 {
                    out[j * coarse.width + i] = (sum / weight) as f32;
                }
            }
        }
        out
    }

    /// One level as the sink saw it.
    struct Record {
        /// Its samples, NaN until seen.
        values: Vec<f32>,
        /// First TMS row and tile rows.
        ty0: u32,
        tiles_y: u32,
        /// Tile rows handed out so far.
        handed: u32,
    }

    /// Copies every row the sink is handed into whole levels, reads each tile row's halo,
    /// and checks the order promises of [`stream_levels`].
    struct Recorder {
        levels: Vec<Record>,
        done: Vec<u8>,
        max_zoom: u8,
    }

    impl LevelSink for Recorder {
        fn tile_rows(&mut self, level: &LevelRows, tile_rows: Range<u32>) -> TerrainResult<()> {
            let z = usize::from(level.level);
            assert!(!self.done.contains(&level.level));
            assert_eq!(
                self.levels[z].handed, tile_rows.start,
                "tile rows in order, once"
            );
            let n = level.tiling.cells as usize;
            for t in tile_rows.clone() {
                let j0 = t as usize * n;
                for j in j0.saturating_sub(1)..=(j0 + n + 1).min(level.height - 1) {
                    for i in 0..level.width {
                        let v = level.at(i, j) as f32;
                        let slot = &mut self.levels[z].values[j * level.width + i];
                        assert!(slot.is_nan() || slot.to_bits() == v.to_bits());
                        *slot = v;
                    }
                }
                // Finer tile rows inside this one's footprint were all handed out.
                let row = level.ty0 + t;
                for (k, finer) in self.levels[z + 1..].iter().enumerate() {
                    let f = 1u32 << (k + 1);
                    let start = (row * f).max(finer.ty0);
                    let end = ((row + 1) * f).min(finer.ty0 + finer.tiles_y);
                    assert!(
                        start >= end || end <= finer.ty0 + finer.handed,
                        "level {}: rows {start}..{end} not all handed out before {}/{row}",
                        z + k + 1,
                        level.level
                    );
                }
            }
            self.levels[z].handed = tile_rows.end;
            Ok(())
        }

        fn level_done(&mut self, level: u8, _seconds: f64) -> TerrainResult<()> {
            // Finest first.
            assert_eq!(self.max_zoom - self.done.len() as u8, level);
            self.done.push(level);
            Ok(())
        }
    }

    fn same(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
    }

    #[test]
    fn streamed_levels_equal_whole_levels_for_any_band_height() {
        // 3 x 4 tiles at level 5 (tiles of 5.625 degrees), a hole across tile edges; the
        // coarser levels start on an even finer row (level 4) and on an odd one (3, 2).
        let bounds = GeoBounds {
            west: 10.3,
            south: 35.0,
            east: 21.0,
            north: 52.0,
            resolution: 0.02,
        };
        for cells in LATTICE_CELLS {
            let scheme = Scheme {
                tiling: Tiling::Geographic,
                cells,
            };
            check_streamed_levels(scheme, &bounds, [11.25, 45.0, 1.5], (2, 5));
        }
    }

    #[test]
    fn streamed_web_mercator_levels_equal_whole_levels_resampled_alike() {
        // Web Mercator tiles from 35 to 68 degrees north (where a tile's Web Mercator
        // middle is far from its latitude middle, coarse rows read finer rows tens of rows
        // away), a hole across tile edges.
        let bounds = GeoBounds {
            west: 10.3,
            south: 35.0,
            east: 30.0,
            north: 68.0,
            resolution: 0.04,
        };
        for cells in LATTICE_CELLS {
            let scheme = Scheme {
                tiling: Tiling::Mercator,
                cells,
            };
            check_streamed_levels(scheme, &bounds, [22.5, 55.77, 1.5], (1, 5));
        }
    }

    /// Streams made-up hills over `bounds` (with a nodata disc `hole`) for `zooms` in
    /// `tiling`, in several band heights and thread counts, and checks every level against
    /// the whole levels made at once (Web Mercator: within float rounding, the reference
    /// placing rows by another computation).
    fn check_streamed_levels(
        tiling: Scheme,
        bounds: &GeoBounds,
        hole: [f64; 3],
        (min_zoom, max_zoom): (u8, u8),
    ) {
        let source = Hills { hole };
        let level = |z: u8| LevelRows::new(TileRect::covering(bounds, tiling, z));
        // The whole levels, made at once.
        let mut whole = Vec::new();
        let finest = level(max_zoom);
        whole.push(
            source
                .rows(&finest, 0..finest.height, 0..finest.width)
                .unwrap(),
        );
        for z in (min_zoom..max_zoom).rev() {
            let (fine, coarse) = (level(z + 1), level(z));
            let values = match tiling.tiling {
                Tiling::Geographic => whole_coarser(&fine, whole.last().unwrap(), &coarse),
                Tiling::Mercator => whole_coarser_mercator(&fine, whole.last().unwrap(), &coarse),
            };
            whole.push(values);
        }
        whole.reverse(); // coarsest first, index z - min_zoom
        let finest_values = whole.last().unwrap();
        assert!(
            finest_values.iter().any(|v| v.is_nan()) && finest_values.iter().any(|v| v.is_finite())
        );

        for (band_rows, threads) in [(1, 1), (1, 3), (2, 2), (100, 2)] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut recorder = Recorder {
                levels: (0..=max_zoom)
                    .map(|z| {
                        let l = level(z);
                        Record {
                            values: vec![f32::NAN; l.width * l.height],
                            ty0: l.ty0,
                            tiles_y: l.tiles_y,
                            handed: 0,
                        }
                    })
                    .collect(),
                done: Vec::new(),
                max_zoom,
            };
            stream_levels(
                &source,
                &level,
                (min_zoom, max_zoom),
                band_rows,
                &pool,
                &mut recorder,
            )
            .unwrap();
            assert_eq!(
                recorder.done,
                (min_zoom..=max_zoom).rev().collect::<Vec<_>>()
            );
            for z in min_zoom..=max_zoom {
                let streamed = &recorder.levels[usize::from(z)].values;
                let reference = &whole[usize::from(z - min_zoom)];
                let agree = match tiling.tiling {
                    Tiling::Geographic => same(streamed, reference),
                    Tiling::Mercator => close(streamed, reference),
                };
                assert!(
                    agree,
                    "level {z}, bands of {band_rows} tile rows, {threads} threads"
                );
            }
        }
    }

    /// Within float rounding of each other, NaN where the other is.
    fn close(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x.is_nan() && y.is_nan()) || (x - y).abs() <= 1e-3 * (1.0 + x.abs()))
    }

    /// The next coarser level of a whole finer Web Mercator level: each coarse row's
    /// filter taps are rows of a lattice half as fine as its own (even in latitude inside
    /// the coarse tile), each interpolated in latitude between the two finer rows around
    /// it, found by bisecting the finer rows' latitudes (not by inverting Web Mercator as
    /// [`LevelRows::coarser_rows`] does); the valid one of the two when only one is.
    fn whole_coarser_mercator(
        fine: &LevelRows,
        fine_values: &[f32],
        coarse: &LevelRows,
    ) -> Vec<f32> {
        let c = i64::from(fine.tiling.cells);
        let (fx0, fy0) = (i64::from(fine.tx0) * c, i64::from(fine.ty0) * c);
        let (cx0, cy0) = (i64::from(coarse.tx0) * c, i64::from(coarse.ty0) * c);
        let coarse_tiles = 1i64 << coarse.level;
        let fine_rows = 2 * coarse_tiles * c + 1;
        let fine_lat: Vec<f64> = (0..fine_rows)
            .map(|r| fine.tiling.row_latitude(fine.level, r))
            .collect();
        let at = |gx: i64, gy: i64| -> f32 {
            let (i, j) = (gx - fx0, gy - fy0);
            if i < 0 || j < 0 || i >= fine.width as i64 || j >= fine.height as i64 {
                f32::NAN
            } else {
                fine_values[j as usize * fine.width + i as usize]
            }
        };
        let half_lat = |h: i64| {
            let t = (h / (2 * c)).min(coarse_tiles - 1);
            let k = h - 2 * c * t;
            let edge =
                |t: i64| tinsmith_raster::web_mercator_latitude(t as f64 / coarse_tiles as f64);
            edge(t) + (edge(t + 1) - edge(t)) * (k as f64 / (2 * c) as f64)
        };
        let taps = [(-2, 1.0), (-1, 4.0), (0, 6.0), (1, 4.0), (2, 1.0)];
        let mut out = vec![f32::NAN; coarse.width * coarse.height];
        for j in 0..coarse.height {
            for i in 0..coarse.width {
                let gx = 2 * (cx0 + i as i64);
                let (mut sum, mut weight) = (0.0f64, 0.0f64);
                for (dy, wy) in taps {
                    let h = 2 * (cy0 + j as i64) + dy;
                    if h < 0 || h > 2 * c * coarse_tiles {
                        continue;
                    }
                    let lat = half_lat(h);
                    let below = (fine_lat.partition_point(|&l| l <= lat) as i64 - 1).max(0);
                    let above = (below + 1).min(fine_rows - 1);
                    let w = if below == above {
                        0.0
                    } else {
                        (lat - fine_lat[below as usize])
                            / (fine_lat[above as usize] - fine_lat[below as usize])
                    };
                    for (dx, wx) in taps {
                        let a = f64::from(at(gx + dx, below));
                        let v = if w <= 0.0 {
                            a
                        } else {
                            let b = f64::from(at(gx + dx, above));
                            match (a.is_finite(), b.is_finite()) {
                                (true, true) => a + (b - a) * w,
                                (true, false) => a,
                                _ => b,
                            }
                        };
                        if v.is_finite() {
                            sum += wx * wy * v;
                            weight += wx * wy;
                        }
                    }
                }
                if weight > 0.0 {
                    out[j * coarse.width + i] = (sum / weight) as f32;
                }
            }
        }
        out
    }

    #[test]
    fn bands_complete_tile_rows() {
        let bounds = GeoBounds {
            west: 0.0,
            south: 0.0,
            east: 50.0,
            north: 50.0,
            resolution: 0.1,
        };
        let level = LevelRows::new(TileRect::covering(&bounds, Scheme::GEOGRAPHIC, 3));
        assert_eq!(level.tiles_y, 3);
        let n = Scheme::GEOGRAPHIC.cells as usize;
        assert_eq!(
            bands(&level, 1),
            vec![0..n + 2, n + 2..2 * n + 2, 2 * n + 2..3 * n + 1]
        );
        assert_eq!(bands(&level, 2), vec![0..2 * n + 2, 2 * n + 2..3 * n + 1]);
        assert_eq!(bands(&level, 5), vec![0..3 * n + 1]);
    }
}
