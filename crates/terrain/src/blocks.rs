//! A pyramid cut into blocks: every tile of the *split* level and the tiles under it are
//! built from a window of the raster around that tile alone, and the levels above the
//! split are filtered from the split level's samples, which the blocks hand over. A block
//! is the unit a run (or a shard of a run) works on; the cut changes how the work is done,
//! never the tiles.

use std::collections::BTreeMap;
use std::ops::Range;

use tinsmith_raster::GeoBounds;

use crate::rows::{LevelRows, Reach};
use crate::stream::RowSource;
use crate::tms::{Scheme, TileRect, Tiling};
use crate::TerrainResult;

/// The most levels from a block's tile down to the raster's own level: a block's window
/// there is at most 16 x 16 tiles (and a ring of one), so its rows stay small.
pub(super) const BLOCK_DEPTH: u8 = 4;

/// Where the pyramid is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Cut {
    /// The pyramid's tiling.
    pub(super) tiling: Scheme,
    /// The raster's own level: it is sampled from the raster, and every coarser level is
    /// filtered from it; finer levels are each sampled alone.
    pub(super) anchor: u8,
    /// The level whose tiles are the blocks (at most the anchor, at least
    /// `anchor - BLOCK_DEPTH`).
    pub(super) split: u8,
}

impl Cut {
    /// The coarsest split the block depth allows: the fewest blocks.
    pub(super) fn coarsest(tiling: Scheme, anchor: u8) -> Cut {
        Cut {
            tiling,
            anchor,
            split: lowest_split(tiling, anchor),
        }
    }
}

/// The coarsest level a pyramid anchored at `anchor` may be split at: [`BLOCK_DEPTH`]
/// levels above the anchor. A Web Mercator pyramid's rows reach further (see
/// [`reach_margin`]): where the margin at the anchor would pass a block window's ring of
/// one tile, it is split at level 0 instead (one block, whose window is the whole
/// domain), which happens only for anchors up to level 7 (tiles of 2.8° and coarser).
pub(super) fn lowest_split(tiling: Scheme, anchor: u8) -> u8 {
    let split = anchor.saturating_sub(BLOCK_DEPTH);
    if split_fits(tiling, split, anchor) {
        split
    } else {
        0
    }
}

/// Whether a pyramid anchored at `anchor` may be split at `split`: level 0 (a single
/// block), or at most [`BLOCK_DEPTH`] levels above the anchor with the reach at the
/// anchor ([`reach_margin`]) within a block window's ring of one tile.
pub(super) fn split_fits(tiling: Scheme, split: u8, anchor: u8) -> bool {
    split == 0
        || (split <= anchor
            && split + BLOCK_DEPTH >= anchor
            && reach_margin(tiling, split, anchor).1 <= tiling.cells as usize)
}

/// The tiles of `level` a pyramid over `bounds` covers.
pub(super) fn domain(bounds: &GeoBounds, tiling: Scheme, level: u8) -> TileRect {
    TileRect::covering(bounds, tiling, level)
}

/// The blocks of a cut: every tile of the split level's domain, in TMS row then column
/// order, as 1 x 1 rectangles.
pub(super) fn blocks(bounds: &GeoBounds, cut: Cut) -> Vec<TileRect> {
    let d = domain(bounds, cut.tiling, cut.split);
    (d.y0..d.y0 + d.height)
        .flat_map(|y| {
            (d.x0..d.x0 + d.width).map(move |x| TileRect {
                tiling: cut.tiling,
                level: cut.split,
                x0: x,
                y0: y,
                width: 1,
                height: 1,
            })
        })
        .collect()
}

/// The window a block is built from at `level` (at or below the block's): the tiles under
/// it with a ring of one tile around them, within the level's domain (round the globe when
/// the domain goes all the way round, a turn east when the ring would start west of
/// column 0). Its samples near the block are those of the whole level: the ring holds
/// every sample the block's tiles, their halos and the filter down to the block's level
/// read (at most [`reach_margin`] of [`BLOCK_DEPTH`] levels, 46 of the ring's 151 or 217 samples,
/// which is all [`block_level`] makes of it).
pub(super) fn block_window(bounds: &GeoBounds, block: TileRect, level: u8) -> TileRect {
    let d = domain(bounds, block.tiling, level);
    let f = level - block.level;
    let turn = block.tiling.columns(level) as i64;
    let mut x0 = (i64::from(block.x0) << f) - 1;
    let mut x1 = (i64::from(block.x0 + block.width) << f) + 1;
    let y0 = ((i64::from(block.y0) << f) - 1).max(i64::from(d.y0));
    let y1 = ((i64::from(block.y0 + block.height) << f) + 1).min(i64::from(d.y0 + d.height));
    if d.wraps() {
        if x1 - x0 >= turn {
            return TileRect {
                y0: y0 as u32,
                height: (y1 - y0) as u32,
                ..d
            };
        }
        if x0 < 0 {
            x0 += turn;
            x1 += turn;
        }
    } else {
        // The turns of the block's columns that meet the domain, clipped to it. A domain
        // wider than half a turn (but not all of it) can meet a block in two turns, on
        // either side of its gap: the window then spans both, or the block would lose the
        // tiles of one side.
        let (d0, d1) = (i64::from(d.x0), i64::from(d.x0 + d.width));
        let overlap = |k: i64| (x1 + k * turn).min(d1) - (x0 + k * turn).max(d0);
        let meeting: Vec<i64> = [0, 1, -1].into_iter().filter(|&k| overlap(k) > 0).collect();
        match meeting.as_slice() {
            [] => {
                let k = [0, 1, -1]
                    .into_iter()
                    .max_by_key(|&k| (overlap(k), -k.abs()))
                    .expect("three turns");
                x0 = (x0 + k * turn).max(d0);
                x1 = (x1 + k * turn).min(d1);
            }
            turns => {
                let starts = turns.iter().map(|k| (x0 + k * turn).max(d0));
                let ends = turns.iter().map(|k| (x1 + k * turn).min(d1));
                (x0, x1) = (starts.min().expect("a turn"), ends.max().expect("a turn"));
            }
        }
    }
    TileRect {
        tiling: block.tiling,
        level,
        x0: x0 as u32,
        y0: y0 as u32,
        width: (x1 - x0) as u32,
        height: (y1 - y0) as u32,
    }
}

/// How far (in samples of `level`: columns, rows) beyond a block's tiles the block's
/// levels down to `top` read, where `level` is at or below `top`: a tile reads one sample
/// past its edges (edges, normals, fingerprint), and a sample of level `z` is filtered
/// from samples of `z + 1` up to two steps either side of its double, so the reach
/// doubles and grows by two per level: 1, 4, 10, 22, 46 samples. Web Mercator rows are
/// filtered from rows resampled in latitude ([`LevelRows::coarser_rows`]): each level's
/// row reach grows by the resampling's offset ([`Tiling::max_row_offset`]) and the row
/// interpolated beside it, too.
pub(super) fn reach_margin(tiling: Scheme, top: u8, level: u8) -> (usize, usize) {
    let columns = 3 * (1usize << (level - top)) - 2;
    let rows = (top..level).fold(1usize, |m, z| match tiling.tiling {
        Tiling::Geographic => 2 * m + 2,
        Tiling::Mercator => 2 * m + 3 + tiling.max_row_offset(z),
    });
    (columns, rows)
}

/// The lattice of `level` a block is built from: its window ([`block_window`]), made only
/// within `margin` (columns, rows) samples of the block's tiles (as [`reach_margin`] gives
/// it): the ring beyond is never sampled, nor filtered.
pub(super) fn block_level(
    bounds: &GeoBounds,
    block: TileRect,
    level: u8,
    margin: (usize, usize),
) -> LevelRows {
    let window = block_window(bounds, block, level);
    let rows = LevelRows::new(window);
    let cells = i64::from(block.tiling.cells);
    let f = level - block.level;
    let (margin, row_margin) = (margin.0 as i64, margin.1 as i64);
    // The block's samples, global lattice columns and rows, widened by the margin.
    let west = (i64::from(block.x0) << f) * cells - margin;
    let span = (i64::from(block.width) << f) * cells + 2 * margin;
    let south = (i64::from(block.y0) << f) * cells - row_margin;
    let north = (i64::from(block.y0 + block.height) << f) * cells + row_margin;
    // Columns compare round the globe: a window may lie a turn east of its block.
    let turn = block.tiling.columns(level) as i64 * cells;
    let columns = (0..rows.width as i64)
        .map(|i| {
            let column = i64::from(window.x0) * cells + i;
            span >= turn || (column - west).rem_euclid(turn) <= span
        })
        .collect();
    let first_row = i64::from(window.y0) * cells;
    let local = |row: i64| (row - first_row).clamp(0, rows.height as i64) as usize;
    let reach = Reach {
        rows: local(south)..local(north + 1),
        columns,
    };
    rows.within(reach)
}

/// The samples of the split level's tiles, as the blocks handed them over, keyed by
/// (column, TMS row); tiles without any are nodata.
#[derive(Debug, Default)]
pub(super) struct SplitSamples {
    pub(super) tiles: BTreeMap<(u32, u32), Vec<f32>>,
}

impl RowSource for SplitSamples {
    fn rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>> {
        let n = level.tiling.cells as usize;
        let side = n + 1;
        let mut out = vec![f32::NAN; level.width * rows.len()];
        for (k, j) in rows.enumerate() {
            let tj = (j / n).min(level.tiles_y as usize - 1);
            let oj = j - tj * n;
            let y = level.ty0 + tj as u32;
            for ti in 0..level.tiles_x as usize {
                let x = level.tiling.tile_column(level.level, level.tx0 + ti as u32);
                let Some(tile) = self.tiles.get(&(x, y)) else {
                    continue;
                };
                let row = &tile[oj * side..(oj + 1) * side];
                out[k * level.width + ti * n..][..side].copy_from_slice(row);
            }
        }
        if columns != (0..level.width) {
            out = out
                .chunks_exact(level.width)
                .flat_map(|row| &row[columns.clone()])
                .copied()
                .collect();
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds(west: f64, east: f64) -> GeoBounds {
        GeoBounds {
            west,
            south: -10.0,
            east,
            north: 10.0,
            resolution: 0.01,
        }
    }

    #[test]
    fn windows_ring_their_block_within_the_domain() {
        let b = bounds(0.5, 20.0);
        let block = TileRect {
            tiling: Scheme::GEOGRAPHIC,
            level: 3,
            x0: 8,
            y0: 3,
            width: 1,
            height: 1,
        };
        let d = domain(&b, Scheme::GEOGRAPHIC, 5);
        let w = block_window(&b, block, 5);
        // Tiles 32..36 with a ring, clipped to the domain's columns and rows.
        assert_eq!(w.x0, d.x0.max(31));
        assert!(w.x0 + w.width <= d.x0 + d.width);
        assert!(w.y0 >= d.y0 && w.y0 + w.height <= d.y0 + d.height);
        for x in 32..36 {
            for y in 12..16 {
                if d.contains(x, y) {
                    assert!(w.contains(x, y), "{x} {y}");
                }
            }
        }
    }

    #[test]
    fn a_block_reaches_its_margin_and_no_further() {
        let globe = GeoBounds {
            west: -180.0,
            south: -80.0,
            east: 180.0,
            north: 80.0,
            resolution: 0.05,
        };
        let block = TileRect {
            tiling: Scheme::GEOGRAPHIC,
            level: 2,
            x0: 0,
            y0: 1,
            width: 1,
            height: 1,
        };
        let n = Scheme::GEOGRAPHIC.cells as usize;
        for (level, margin) in [(2, (1, 1)), (4, reach_margin(Scheme::GEOGRAPHIC, 2, 4))] {
            let rows = block_level(&globe, block, level, margin);
            let reach = rows.reach().expect("a block's level has a reach");
            let core = n << (level - 2);
            // The window's first column is a turn east of the block's west edge less a
            // ring tile: the block starts a tile in.
            let first = n;
            assert_eq!(
                reach.column_runs(),
                vec![first - margin.0..first + core + margin.0 + 1],
                "level {level}"
            );
            // The block's southern row, local to the window (which may start at the domain).
            let block_south = ((1usize << (level - 2)) - rows.ty0 as usize) * n;
            assert_eq!(
                reach.rows,
                block_south - margin.1..block_south + core + margin.1 + 1
            );
        }
    }

    #[test]
    fn a_block_at_column_0_of_a_globe_rings_round_the_antimeridian() {
        let b = GeoBounds {
            west: -180.0,
            south: -80.0,
            east: 180.0,
            north: 80.0,
            resolution: 0.05,
        };
        let block = TileRect {
            tiling: Scheme::GEOGRAPHIC,
            level: 2,
            x0: 0,
            y0: 1,
            width: 1,
            height: 1,
        };
        let w = block_window(&b, block, 4);
        // Columns -1 ..= 4 a turn east (32 columns): 31 ..= 36.
        assert_eq!((w.x0, w.width), (31, 6));
        assert!(w.contains(31, 5) && w.contains(0, 5) && w.contains(4, 5));
        assert_eq!(block_window(&b, block, 2).x0, 7);
    }
}
