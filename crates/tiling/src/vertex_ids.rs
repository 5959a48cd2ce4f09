//! Welded vertex numbering: shared edge vertices get one id, owned by the first tile (in
//! tile order) that has them.

use tinsmith_core::TinVertex;

use crate::error::{Error, Result};
use crate::plan::{TileIndex, TilePlan, TileWindow};

/// No id yet.
const NONE: u32 = u32::MAX;

/// Numbers the vertices of tiles handed over in row-major order.
///
/// A vertex on a tile's top row can only have been numbered by a tile of the previous tile
/// row (which saw it on its bottom row), and one on its left column by the tile to its left
/// (its right column). So the welder remembers the ids of the previous tile row's bottom
/// row (one slot per raster column), the current row's bottom row, and the previous tile's
/// right column: memory is O(raster width + tile size), whatever the raster's height.
#[derive(Debug)]
pub(crate) struct Welder {
    plan: TilePlan,
    /// Ids along the current tile row's top raster row, by raster column.
    above: Vec<u32>,
    /// Ids along the current tile row's bottom raster row, by raster column.
    below: Vec<u32>,
    /// Ids along the previous tile's right column, by row within the tile row.
    left: Vec<u32>,
    /// Ids along this tile's right column.
    right: Vec<u32>,
    next_id: u32,
    next_tile: usize,
}

impl Welder {
    pub(crate) fn new(plan: TilePlan) -> Welder {
        let (w, size) = (plan.width() as usize, plan.size() as usize);
        Welder {
            plan,
            above: vec![NONE; w],
            below: vec![NONE; w],
            left: vec![NONE; size],
            right: vec![NONE; size],
            next_id: 0,
            next_tile: 0,
        }
    }

    /// Vertices numbered so far.
    pub(crate) fn vertex_count(&self) -> u32 {
        self.next_id
    }

    /// Numbers the vertices of the next tile (`vertices` in raster coordinates); returns
    /// the id of each and the first new id.
    ///
    /// # Errors
    /// [`Error::TooManyVertices`] when the welded mesh would have 2^32 - 1 vertices.
    ///
    /// # Panics
    /// When `index` is not the next tile in row-major order.
    pub(crate) fn weld(
        &mut self,
        index: TileIndex,
        vertices: &[TinVertex],
    ) -> Result<(Vec<u32>, u32)> {
        assert_eq!(
            self.plan.position(index),
            self.next_tile,
            "tiles out of order"
        );
        self.next_tile += 1;
        let window: TileWindow = self.plan.window(index);
        if index.col == 0 {
            if index.row > 0 {
                std::mem::swap(&mut self.above, &mut self.below);
                self.below.fill(NONE);
            }
            self.right.fill(NONE);
        }
        std::mem::swap(&mut self.left, &mut self.right);
        self.right.fill(NONE);

        let first_new = self.next_id;
        let mut ids = Vec::with_capacity(vertices.len());
        for v in vertices {
            let (lx, ly) = ((v.x - window.x0) as usize, (v.y - window.y0) as usize);
            let mut id = NONE;
            if ly == 0 && index.row > 0 {
                id = self.above[v.x as usize];
            }
            if id == NONE && lx == 0 && index.col > 0 {
                id = self.left[ly];
            }
            if id == NONE {
                if self.next_id == NONE {
                    return Err(Error::TooManyVertices { tile: index });
                }
                id = self.next_id;
                self.next_id += 1;
            }
            if v.y == window.y1() {
                self.below[v.x as usize] = id;
            }
            if v.x == window.x1() {
                self.right[ly] = id;
            }
            ids.push(id);
        }
        Ok((ids, first_new))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn vertex(x: u32, y: u32) -> TinVertex {
        TinVertex { x, y, z: 0.0 }
    }

    /// Every sample of each tile is a vertex except those `skip` drops: ids must be one
    /// per position, numbered in order of first appearance.
    fn check(w: u32, h: u32, size: u32, skip: impl Fn(TileIndex, u32, u32) -> bool) {
        let plan = TilePlan::new(w, h, size).expect("plan");
        let mut welder = Welder::new(plan);
        let mut by_position: HashMap<(u32, u32), u32> = HashMap::new();
        for index in plan.indices() {
            let t = plan.window(index);
            let vertices: Vec<TinVertex> = (t.y0..=t.y1())
                .flat_map(|y| (t.x0..=t.x1()).map(move |x| (x, y)))
                .filter(|&(x, y)| !skip(index, x, y))
                .map(|(x, y)| vertex(x, y))
                .collect();
            let (ids, first_new) = welder.weld(index, &vertices).expect("weld");
            let mut expected_next = first_new;
            for (v, &id) in vertices.iter().zip(&ids) {
                match by_position.get(&(v.x, v.y)) {
                    Some(&old) => assert_eq!(id, old, "{index} at {},{}", v.x, v.y),
                    None => {
                        assert_eq!(id, expected_next, "new ids ascend");
                        expected_next += 1;
                        by_position.insert((v.x, v.y), id);
                    }
                }
            }
            assert_eq!(welder.vertex_count(), expected_next);
        }
        assert_eq!(welder.vertex_count() as usize, by_position.len());
    }

    #[test]
    fn shared_samples_get_one_id() {
        check(10, 7, 4, |_, _, _| false);
        check(5, 5, 2, |_, _, _| false);
        check(9, 12, 3, |_, _, _| false);
    }

    #[test]
    fn samples_missing_from_the_owner_are_new_in_the_next_tile() {
        // Tiles drop some of their edge samples (as nodata would): a sample that an earlier
        // tile lacks is numbered by the first tile that has it.
        check(13, 11, 4, |index, x, y| {
            (x * 7 + y * 3 + index.col * 5) % 4 == 0
        });
        check(7, 7, 3, |index, x, y| {
            index.row % 2 == 0 && (x + y) % 2 == 0 || index.col == 1 && y % 3 == 0
        });
    }

    #[test]
    #[should_panic(expected = "tiles out of order")]
    fn tiles_must_come_in_order() {
        let plan = TilePlan::new(10, 10, 4).expect("plan");
        let mut welder = Welder::new(plan);
        let _ = welder.weld(plan.index(1), &[]);
    }
}
