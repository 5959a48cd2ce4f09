//! The tile plan: how a raster is cut into tiles that share their edge rows and columns.

use std::fmt;

use crate::error::{Error, Result};

/// A tile's place in the plan: its column and row of tiles (0-based, from the raster's
/// top-left corner).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TileIndex {
    /// Tile column.
    pub col: u32,
    /// Tile row.
    pub row: u32,
}

impl fmt::Display for TileIndex {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "tile (row {}, column {})", self.row, self.col)
    }
}

/// The samples of one tile: a rectangle of the raster, in raster coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TileWindow {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// Columns (at least 2).
    pub width: u32,
    /// Rows (at least 2).
    pub height: u32,
}

impl TileWindow {
    /// Last column (inclusive).
    pub fn x1(&self) -> u32 {
        self.x0 + self.width - 1
    }

    /// Last row (inclusive).
    pub fn y1(&self) -> u32 {
        self.y0 + self.height - 1
    }
}

/// How a `width` x `height` raster is cut into tiles of at most `size` x `size` samples.
///
/// Neighbouring tiles share their edge row or column: tile column `c` spans columns
/// `c * (size - 1) ..= min((c + 1) * (size - 1), width - 1)`, and likewise for rows. Every
/// cell of the raster (the square between four neighbouring samples) lies in exactly one
/// tile; the last tile column and row may be narrower, down to 2 samples. Tiles are
/// numbered in row-major order ([`TilePlan::index`]), the order in which they are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TilePlan {
    width: u32,
    height: u32,
    size: u32,
    columns: u32,
    rows: u32,
}

impl TilePlan {
    /// The plan for a `width` x `height` raster and tiles of `size` samples per side,
    /// including the shared row and column.
    ///
    /// # Errors
    /// [`Error::TileSize`] when `size < 2`; [`Error::TooNarrow`] when the raster has fewer
    /// than 2 columns or rows (it has no cell, so nothing to triangulate).
    pub fn new(width: u32, height: u32, size: u32) -> Result<TilePlan> {
        if size < 2 {
            return Err(Error::TileSize { size });
        }
        if width < 2 || height < 2 {
            return Err(Error::TooNarrow { width, height });
        }
        let step = size - 1;
        Ok(TilePlan {
            width,
            height,
            size,
            columns: (width - 1).div_ceil(step),
            rows: (height - 1).div_ceil(step),
        })
    }

    /// Columns of the raster.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows of the raster.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Samples per tile side, shared row and column included.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Tile columns.
    pub fn columns(&self) -> u32 {
        self.columns
    }

    /// Tile rows.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// Number of tiles.
    pub fn len(&self) -> usize {
        self.columns as usize * self.rows as usize
    }

    /// Whether the plan has no tile (never: a plan has at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `i`-th tile in row-major order.
    ///
    /// # Panics
    /// When `i >= self.len()`.
    pub fn index(&self, i: usize) -> TileIndex {
        assert!(i < self.len(), "tile {i} of {}", self.len());
        TileIndex {
            col: (i % self.columns as usize) as u32,
            row: (i / self.columns as usize) as u32,
        }
    }

    /// The position of `index` in row-major order.
    pub fn position(&self, index: TileIndex) -> usize {
        index.row as usize * self.columns as usize + index.col as usize
    }

    /// Every tile, in row-major order.
    pub fn indices(&self) -> impl Iterator<Item = TileIndex> + '_ {
        (0..self.len()).map(|i| self.index(i))
    }

    /// The samples of tile `index`.
    ///
    /// # Panics
    /// When `index` is outside the plan.
    pub fn window(&self, index: TileIndex) -> TileWindow {
        assert!(index.col < self.columns && index.row < self.rows, "{index}");
        let step = self.size - 1;
        let x0 = index.col * step;
        let y0 = index.row * step;
        TileWindow {
            x0,
            y0,
            width: (x0 + step).min(self.width - 1) - x0 + 1,
            height: (y0 + step).min(self.height - 1) - y0 + 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_share_edges_and_cover_every_cell_once() {
        for (w, h, size) in [(10, 7, 4), (2, 2, 2), (5, 9, 2), (17, 17, 5), (100, 3, 64)] {
            let plan = TilePlan::new(w, h, size).expect("plan");
            let mut cells = vec![0u32; ((w - 1) * (h - 1)) as usize];
            for (i, index) in plan.indices().enumerate() {
                assert_eq!(plan.position(index), i);
                let t = plan.window(index);
                assert!(t.width >= 2 && t.height >= 2 && t.width <= size && t.height <= size);
                for cy in t.y0..t.y1() {
                    for cx in t.x0..t.x1() {
                        cells[(cy * (w - 1) + cx) as usize] += 1;
                    }
                }
                if index.col > 0 {
                    let left = plan.window(TileIndex {
                        col: index.col - 1,
                        ..index
                    });
                    assert_eq!(left.x1(), t.x0, "shared column");
                }
                if index.row > 0 {
                    let up = plan.window(TileIndex {
                        row: index.row - 1,
                        ..index
                    });
                    assert_eq!(up.y1(), t.y0, "shared row");
                }
            }
            assert!(cells.iter().all(|&n| n == 1), "{w}x{h} by {size}");
            let last = plan.window(plan.index(plan.len() - 1));
            assert_eq!((last.x1(), last.y1()), (w - 1, h - 1));
        }
    }

    #[test]
    fn counts_for_exact_and_ragged_sizes() {
        let plan = TilePlan::new(1025, 1025, 257).expect("plan");
        assert_eq!((plan.columns(), plan.rows(), plan.len()), (4, 4, 16));
        let plan = TilePlan::new(1026, 1024, 257).expect("plan");
        assert_eq!((plan.columns(), plan.rows()), (5, 4));
        assert_eq!(plan.window(TileIndex { col: 4, row: 0 }).width, 2);
        assert_eq!(plan.window(TileIndex { col: 0, row: 3 }).height, 256);
        let plan = TilePlan::new(300, 200, 1000).expect("plan");
        assert_eq!(plan.len(), 1);
        assert_eq!(
            plan.window(plan.index(0)),
            TileWindow {
                x0: 0,
                y0: 0,
                width: 300,
                height: 200
            }
        );
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert!(matches!(
            TilePlan::new(10, 10, 1),
            Err(Error::TileSize { size: 1 })
        ));
        assert!(matches!(
            TilePlan::new(1, 10, 4),
            Err(Error::TooNarrow { .. })
        ));
        assert!(matches!(
            TilePlan::new(10, 1, 4),
            Err(Error::TooNarrow { .. })
        ));
    }

    #[test]
    fn display_names_row_and_column() {
        assert_eq!(
            TileIndex { col: 5, row: 3 }.to_string(),
            "tile (row 3, column 5)"
        );
    }
}
