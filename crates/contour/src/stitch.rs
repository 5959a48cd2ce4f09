//! Contouring a mesh that arrives in pieces (the tiles of a tiled decimation), holding the
//! lines but never the whole mesh.

use std::collections::{HashMap, VecDeque};

use crate::join::{finish_line, sort_lines, walk_levels, Crossing};
use crate::regularize::without_zero_width_parts;
use crate::{levels::sorted_levels, ContourMesh, Error, Polyline, Result};

/// The contour lines of a mesh given piece by piece: exactly what [`crate::contour`] gives
/// on the whole mesh, holding only the lines (finished, and the parts still waiting for a
/// neighbouring piece) rather than the mesh.
///
/// Each piece is a [`ContourMesh`] with an id for each of its vertices; pieces meet where
/// they share vertex ids, as the tiles of a welded mesh do (`tinsmith-tiling` numbers a tile
/// edge's vertices once for both tiles). A line crossing from piece to piece is walked in
/// each and its parts are joined through the edge, named by its two ids, where one part
/// leaves and the next enters, in whatever order the pieces come.
///
/// # Requirements
/// Together the pieces must form one mesh in which every edge is shared by at most two
/// triangles, with a vertex id always naming the same position and height (otherwise the
/// lines are those of some other surface, or [`ContourStitcher::add`] reports an internal
/// error). Pieces must use the same orientation convention for the plane (all given in the
/// same coordinates).
///
/// # Determinism
/// The output order is [`crate::contour`]'s (by level, then by the edge under a line's
/// first point), whatever the order of the pieces; hash maps are only looked up, never
/// iterated.
#[derive(Debug)]
pub struct ContourStitcher {
    levels: Vec<f64>,
    /// Open parts waiting for a neighbour, by slot; `None` slots are free.
    parts: Vec<Option<Part>>,
    free: Vec<usize>,
    /// Where a waiting part's line enters (its first crossing's edge), by level index.
    by_entry: HashMap<(u32, [u32; 2]), usize>,
    /// Where a waiting part's line leaves (its last crossing's edge), by level index.
    by_exit: HashMap<(u32, [u32; 2]), usize>,
    lines: Vec<Polyline>,
    /// Crossings held in waiting parts and finished lines, for sizing.
    held: u64,
}

/// A line's parts joined so far, entry to exit: the pieces' walks in order, each after the
/// first without the crossing it shares with the one before. Kept as a list so that
/// joining two parts moves the shorter list into the longer one instead of copying
/// crossings (a line crossing many tiles against their order would otherwise be copied
/// once per tile).
#[derive(Debug)]
struct Part {
    level: u32,
    walks: VecDeque<Vec<Crossing>>,
}

impl Part {
    fn exit(&self) -> [u32; 2] {
        let last = self.walks.back().expect("a part has a walk");
        last[last.len() - 1].edge
    }

    fn into_crossings(self) -> Vec<Crossing> {
        let mut all = Vec::with_capacity(self.walks.iter().map(Vec::len).sum());
        for walk in self.walks {
            all.extend(walk);
        }
        all
    }
}

impl ContourStitcher {
    /// A stitcher for `levels` (any order; duplicates are contoured once).
    ///
    /// # Errors
    /// [`Error::InvalidLevel`] for a NaN or infinite level.
    pub fn new(levels: &[f64]) -> Result<ContourStitcher> {
        Ok(ContourStitcher {
            levels: sorted_levels(levels)?,
            parts: Vec::new(),
            free: Vec::new(),
            by_entry: HashMap::new(),
            by_exit: HashMap::new(),
            lines: Vec::new(),
            held: 0,
        })
    }

    /// Contours one piece, whose vertex `i` has id `ids[i]`, and joins its lines with the
    /// parts of earlier pieces.
    ///
    /// # Errors
    /// [`Error::Internal`] when two parts would enter (or leave) through the same edge at
    /// one level, as when a piece is added twice. Other overlaps (a ring added twice, a
    /// piece inside another) are not detected: see the requirements above.
    ///
    /// # Panics
    /// When `ids` does not have one id per vertex of `piece`.
    pub fn add(&mut self, piece: &ContourMesh, ids: &[u32]) -> Result<()> {
        assert_eq!(ids.len(), piece.vertices().len(), "one id per vertex");
        let levels = std::mem::take(&mut self.levels);
        let result = walk_levels(piece, &levels, Some(ids), |index, level, walk| {
            self.held += walk.crossings.len() as u64;
            if walk.closed {
                self.lines.extend(finish_line(level, true, walk.crossings));
                Ok(())
            } else {
                self.join(index as u32, level, walk.crossings)
            }
        });
        self.levels = levels;
        result
    }

    /// How many crossings (points, before merging) the lines and waiting parts hold so far:
    /// memory grows by about 24 bytes for each.
    pub fn crossings_held(&self) -> u64 {
        self.held
    }

    /// The lines, in [`crate::contour`]'s order. Parts still waiting end on edges no other
    /// piece shares: the outline of the whole mesh or a hole in it.
    pub fn finish(mut self) -> Vec<Polyline> {
        for part in self.parts.into_iter().flatten() {
            let level = self.levels[part.level as usize];
            self.lines
                .extend(finish_line(level, false, part.into_crossings()));
        }
        let mut lines = without_zero_width_parts(self.lines);
        sort_lines(&mut lines);
        lines
    }

    /// Joins an open part (entry to exit) with the waiting parts it meets.
    fn join(&mut self, level_index: u32, level: f64, mut crossings: Vec<Crossing>) -> Result<()> {
        let overlap = Error::Internal {
            level,
            what: "two pieces cross the same edge in the same direction",
        };
        let entry = (level_index, crossings[0].edge);
        let exit = (level_index, crossings[crossings.len() - 1].edge);
        // The part the new one continues, or a new slot.
        let slot = match self.by_exit.remove(&entry) {
            Some(before) => {
                // The shared crossing is the last of the part before.
                crossings.remove(0);
                let part = self.parts[before].as_mut().expect("waiting part");
                part.walks.push_back(crossings);
                before
            }
            None => {
                if self.by_entry.contains_key(&entry) {
                    return Err(overlap);
                }
                let part = Part {
                    level: level_index,
                    walks: VecDeque::from([crossings]),
                };
                let slot = match self.free.pop() {
                    Some(slot) => {
                        self.parts[slot] = Some(part);
                        slot
                    }
                    None => {
                        self.parts.push(Some(part));
                        self.parts.len() - 1
                    }
                };
                self.by_entry.insert(entry, slot);
                slot
            }
        };
        // The part that continues it, if any.
        match self.by_entry.get(&exit).copied() {
            Some(after) if after == slot => {
                // Back at its own start: a ring.
                self.by_entry.remove(&exit);
                let part = self.parts[slot].take().expect("waiting part");
                self.free.push(slot);
                self.lines
                    .extend(finish_line(level, true, part.into_crossings()));
            }
            Some(after) => {
                self.by_entry.remove(&exit);
                let mut next = self.parts[after].take().expect("waiting part");
                self.free.push(after);
                let next_exit = (level_index, next.exit());
                // The shared crossing is the last of this part.
                next.walks.front_mut().expect("a part has a walk").remove(0);
                let part = self.parts[slot].as_mut().expect("waiting part");
                if part.walks.len() >= next.walks.len() {
                    part.walks.extend(next.walks);
                } else {
                    while let Some(walk) = part.walks.pop_back() {
                        next.walks.push_front(walk);
                    }
                    part.walks = next.walks;
                }
                self.by_exit.insert(next_exit, slot);
            }
            None => {
                if self.by_exit.insert(exit, slot).is_some() {
                    return Err(overlap);
                }
            }
        }
        Ok(())
    }
}
