//! A cheap initial mesh: every row (or every column) simplified as a 1-D polyline within
//! the limit, and each pair of adjacent simplified lines zipped into triangles (beyond the
//! paper). On a grid with variables a line keeps a sample where any field needs it: the
//! height within the limit, each variable within what the exact model accepts of it.
//!
//! A triangle between two adjacent lines holds samples only on those two lines, and on a
//! line only along its own edge there (a diagonal between adjacent lines passes through
//! no other sample). So its error is the 1-D error of one line segment, and each line can
//! be simplified on its own. The 1-D simplification is one pass per line, with no
//! triangle measured more than once, so this start costs a fraction of the RTIN's
//! ([`crate::rtin`]); it also keeps fewer samples wherever the bound is small relative to
//! the ground's roughness, where the RTIN must keep most of its finest level.
//!
//! # Guarantees
//! Every emitted triangle lies in the domain (all cells in its bounding box are valid)
//! and its exact error, measured with [`triangle_error`], is within the limit; every valid
//! cell is covered; every sample where the domain's outline turns or pinches is a vertex.
//! With `full_border`, every triangle that reaches the grid's outer rows or columns is a
//! half cell, as [`crate::decimate_with_border`] needs.

use crate::edge_limit::EdgeLimit;
use crate::exact::triangle_error;
use crate::mesh::CompactBound;
use crate::predicates::{orient, Point};
#[cfg(test)]
use crate::ErrorBound;
use crate::Grid;

/// The 1-D pass calls its `tick` once every this many lines.
pub(crate) const TICK_LINES: usize = 64;

/// [`StripPlan::triangles`] calls its `tick` once every this many triangles measured.
pub(crate) const TICK_TRIANGLES: usize = 1 << 14;

/// The strip start planned: its lines simplified, its triangles not yet made.
pub(crate) struct StripPlan<'g> {
    grid: &'g Grid,
    limit: f64,
    lines: Lines,
    kept: Kept,
    /// How many triangles [`StripPlan::triangles`] makes (counted once, by a zip pass).
    triangle_count: usize,
}

impl<'g> StripPlan<'g> {
    /// Simplifies the rows and the columns within `limit` and keeps whichever keep fewer
    /// samples (rows on a tie); `None` if the grid is less than two samples wide or high.
    /// `tick` is called every [`TICK_LINES`] lines.
    pub(crate) fn new(
        grid: &'g Grid,
        limit: f64,
        full_border: bool,
        tick: &dyn Fn(),
    ) -> Option<StripPlan<'g>> {
        if grid.width() < 2 || grid.height() < 2 {
            return None;
        }
        let rows = Lines::new(grid, true);
        let columns = Lines::new(grid, false);
        let along_rows = kept_samples(grid, rows, limit, full_border, tick);
        let along_columns = kept_samples(grid, columns, limit, full_border, tick);
        let (lines, kept) = if along_columns.positions.len() < along_rows.positions.len() {
            (columns, along_columns)
        } else {
            (rows, along_rows)
        };
        let mut plan = StripPlan {
            grid,
            limit,
            lines,
            kept,
            triangle_count: 0,
        };
        let mut count = 0;
        plan.zip(|_, _, _| {
            count += 1;
            Some(())
        });
        plan.triangle_count = count;
        Some(plan)
    }

    /// How many samples the simplified lines keep.
    pub(crate) fn kept_count(&self) -> usize {
        self.kept.positions.len()
    }

    /// How many triangles [`StripPlan::triangles`] makes.
    pub(crate) fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// The triangles (counter-clockwise sample indices, in row-major order of their
    /// first corner's row) with their exact errors; `None` if one measured above the
    /// limit after all (the 1-D pass works in floating point, the measurement decides),
    /// or one is turned over on `edge_limit`'s sphere ([`EdgeLimit::faces_out`]: a strip
    /// triangle is thin, and a long edge along a row bulges poleward as drawn).
    /// `tick` is called every [`TICK_TRIANGLES`] triangles.
    pub(crate) fn triangles(
        &self,
        edge_limit: &EdgeLimit,
        tick: &dyn Fn(),
    ) -> Option<(Vec<[u32; 3]>, Vec<CompactBound>)> {
        let grid = self.grid;
        let width = self.lines.width;
        let point = |i: usize| Point {
            x: (i % width) as i64,
            y: (i / width) as i64,
            z: grid.vertex_height(i),
        };
        let mut corners = Vec::with_capacity(self.triangle_count);
        let mut bounds = Vec::with_capacity(self.triangle_count);
        self.zip(|a, b, c| {
            let (pa, pb, pc) = (point(a), point(b), point(c));
            let (b, c, pb, pc) = if orient(&pa, &pb, &pc) > 0 {
                (b, c, pb, pc)
            } else {
                (c, b, pc, pb)
            };
            if !edge_limit.faces_out(&pa, &pb, &pc) {
                return None;
            }
            let bound = triangle_error(grid, &pa, &pb, &pc, self.limit)?;
            if corners.len().is_multiple_of(TICK_TRIANGLES) {
                tick();
            }
            corners.push([a as u32, b as u32, c as u32]);
            bounds.push(CompactBound::from(bound));
            Some(())
        })?;
        if self.lines.along_rows {
            Some((corners, bounds))
        } else {
            Some(in_row_order(grid, corners, bounds))
        }
    }

    /// Zips each strip's runs of valid cells into triangles (the shorter diagonal first),
    /// calling `emit` with each one's sample indices (in either orientation); stops at
    /// the first `None` it returns.
    fn zip(&self, mut emit: impl FnMut(usize, usize, usize) -> Option<()>) -> Option<()> {
        let (grid, lines, kept) = (self.grid, self.lines, &self.kept);
        for strip in 0..lines.count() - 1 {
            let (near, far) = (kept.line(strip), kept.line(strip + 1));
            let (mut i, mut j) = (0, 0);
            let mut pos = 0;
            while pos + 1 < lines.len() {
                if !lines.cell_valid(grid, strip, pos) {
                    pos += 1;
                    continue;
                }
                let mut end = pos + 1;
                while lines.cell_valid(grid, strip, end) {
                    end += 1;
                }
                // Both lines keep `pos` and `end` (a run's ends are always kept).
                while near[i] as usize != pos {
                    i += 1;
                }
                while far[j] as usize != pos {
                    j += 1;
                }
                while near[i] as usize != end || far[j] as usize != end {
                    let advance_near = far[j] as usize == end
                        || (near[i] as usize != end
                            && near[i + 1].abs_diff(far[j]) <= far[j + 1].abs_diff(near[i]));
                    if advance_near {
                        emit(
                            lines.sample(strip, near[i] as usize),
                            lines.sample(strip, near[i + 1] as usize),
                            lines.sample(strip + 1, far[j] as usize),
                        )?;
                        i += 1;
                    } else {
                        emit(
                            lines.sample(strip, near[i] as usize),
                            lines.sample(strip + 1, far[j + 1] as usize),
                            lines.sample(strip + 1, far[j] as usize),
                        )?;
                        j += 1;
                    }
                }
                pos = end;
            }
        }
        Some(())
    }
}

/// The grid seen as lines: its rows, or its columns.
#[derive(Debug, Clone, Copy)]
struct Lines {
    along_rows: bool,
    width: usize,
    height: usize,
}

impl Lines {
    fn new(grid: &Grid, along_rows: bool) -> Lines {
        Lines {
            along_rows,
            width: grid.width() as usize,
            height: grid.height() as usize,
        }
    }

    /// How many lines there are.
    fn count(&self) -> usize {
        if self.along_rows {
            self.height
        } else {
            self.width
        }
    }

    /// Samples per line.
    fn len(&self) -> usize {
        if self.along_rows {
            self.width
        } else {
            self.height
        }
    }

    /// The sample index of position `pos` on line `line`.
    fn sample(&self, line: usize, pos: usize) -> usize {
        if self.along_rows {
            line * self.width + pos
        } else {
            pos * self.width + line
        }
    }

    /// Whether the cell between lines `strip` and `strip + 1` and positions `pos` and
    /// `pos + 1` is valid; cells outside the grid are not.
    fn cell_valid(&self, grid: &Grid, strip: usize, pos: usize) -> bool {
        if strip + 1 >= self.count() || pos + 1 >= self.len() {
            return false;
        }
        if self.along_rows {
            grid.cell_is_valid(pos, strip)
        } else {
            grid.cell_is_valid(strip, pos)
        }
    }
}

/// The kept positions of every line, line after line, in increasing position.
struct Kept {
    positions: Vec<u32>,
    /// `positions[starts[l]..starts[l + 1]]` are line `l`'s.
    starts: Vec<usize>,
}

impl Kept {
    fn line(&self, line: usize) -> &[u32] {
        &self.positions[self.starts[line]..self.starts[line + 1]]
    }
}

/// How many samples the strips along rows keep (one of the two passes of
/// [`StripPlan::new`]).
pub(crate) fn kept_along_rows(
    grid: &Grid,
    limit: f64,
    full_border: bool,
    tick: &dyn Fn(),
) -> usize {
    if grid.width() < 2 || grid.height() < 2 {
        return grid.values().len();
    }
    kept_samples(grid, Lines::new(grid, true), limit, full_border, tick)
        .positions
        .len()
}

/// An estimate of how many samples [`StripPlan::new`] keeps on a grid without nodata:
/// along rows and along columns, every `step`-th line (from the first) simplified exactly
/// as the plan simplifies it, the count scaled to all lines; the smaller of the two, as
/// the plan takes. Depends only on the arguments; costs about `1 / step` of the plan.
pub(crate) fn estimated_kept(grid: &Grid, limit: f64, full_border: bool, step: usize) -> usize {
    if grid.width() < 2 || grid.height() < 2 {
        return grid.values().len();
    }
    debug_assert_eq!(
        grid.valid_cell_count(),
        (grid.width() as usize - 1) * (grid.height() as usize - 1)
    );
    [true, false]
        .map(|along_rows| {
            estimated_kept_along(grid, Lines::new(grid, along_rows), limit, full_border, step)
        })
        .into_iter()
        .min()
        .expect("two directions")
}

/// [`estimated_kept`] along one direction.
fn estimated_kept_along(
    grid: &Grid,
    lines: Lines,
    limit: f64,
    full_border: bool,
    step: usize,
) -> usize {
    let (count, len) = (lines.count(), lines.len());
    let step = step.max(1);
    let mut segment = Segment::new(grid, limit, len);
    let mut must = Vec::new();
    let (mut kept, mut sampled) = (0usize, 0usize);
    for line in (0..count).step_by(step) {
        // Every cell is valid: a line's run of cells spans it, so its ends are kept, and
        // with a full border so are its outer two positions (every position of the
        // outer two lines), as in `kept_samples`.
        let outer_line = full_border && (line <= 1 || line + 2 >= count);
        must.clear();
        must.extend((0..len).filter(|&pos| {
            pos == 0
                || pos + 1 == len
                || outer_line
                || (full_border && (pos <= 1 || pos + 2 >= len))
        }));
        sampled += 1;
        kept += must.len();
        for pair in must.windows(2) {
            let (pos, next) = (pair[0], pair[1]);
            if next == pos + 1 {
                continue;
            }
            segment.load(&lines, line, pos..=next);
            segment.simplify(|_| kept += 1);
        }
    }
    kept.saturating_mul(count) / sampled
}

/// Simplifies every line: the positions where a strip's run of valid cells begins or ends
/// (and, with `full_border`, every position of the two outer lines on each side and the
/// two outer positions at each end of every line) are kept, and each stretch between two
/// of them that borders a valid cell is simplified within `limit`.
fn kept_samples(grid: &Grid, lines: Lines, limit: f64, full_border: bool, tick: &dyn Fn()) -> Kept {
    let (count, len) = (lines.count(), lines.len());
    let mut kept = Kept {
        positions: Vec::new(),
        starts: Vec::with_capacity(count + 1),
    };
    let mut segment = Segment::new(grid, limit, len);
    let mut must = Vec::new();
    // Cell validity of the strips before and after the current line, one entry per
    // position (the last always invalid: no cell starts there).
    let all_valid = grid.valid_cell_count() == (lines.width - 1) * (lines.height - 1);
    let strip_cells = |strip: Option<usize>, cells: &mut Vec<bool>| {
        cells.clear();
        cells.extend((0..len).map(|pos| {
            strip.is_some_and(|s| {
                if all_valid {
                    s + 1 < count && pos + 1 < len
                } else {
                    lines.cell_valid(grid, s, pos)
                }
            })
        }));
    };
    let (mut before, mut after) = (Vec::with_capacity(len), Vec::with_capacity(len));
    strip_cells(None, &mut before);
    for line in 0..count {
        if line.is_multiple_of(TICK_LINES) {
            tick();
        }
        kept.starts.push(kept.positions.len());
        if line > 0 {
            std::mem::swap(&mut before, &mut after);
        }
        strip_cells(Some(line), &mut after);
        let outer_line = full_border && (line <= 1 || line + 2 >= count);
        must.clear();
        let mut left = (false, false);
        for pos in 0..len {
            let right = (before[pos], after[pos]);
            if left != right
                || ((right.0 || right.1)
                    && (outer_line || (full_border && (pos <= 1 || pos + 2 >= len))))
            {
                must.push(pos);
            }
            left = right;
        }
        for (k, &pos) in must.iter().enumerate() {
            kept.positions.push(pos as u32);
            let Some(&next) = must.get(k + 1) else {
                break;
            };
            if next == pos + 1 || !(before[pos] || after[pos]) {
                continue;
            }
            segment.load(&lines, line, pos..=next);
            segment.simplify(|p| kept.positions.push((pos + p) as u32));
        }
    }
    kept.starts.push(kept.positions.len());
    kept
}

/// A stretch of a line loaded for the 1-D pass: the height's samples and vertex heights,
/// and each constrained variable's values (its own vertex heights), each field with the
/// bound it must keep.
struct Segment<'g> {
    grid: &'g Grid,
    limit: f64,
    z: Vec<f64>,
    heights: Vec<f64>,
    /// Per constrained variable: its grid, its bound (the difference the exact model
    /// accepts of it with the height within `limit`, see `Measured::cap`), its values
    /// along the stretch and its cone of slopes.
    variables: Vec<VariableStretch<'g>>,
    /// `1 / k` for every run length `k` of the line.
    reciprocals: Vec<f64>,
    /// How many positions are loaded.
    n: usize,
}

/// One variable's part of a [`Segment`].
struct VariableStretch<'g> {
    grid: &'g Grid,
    bound: f64,
    values: Vec<f64>,
    cone: (f64, f64),
}

impl<'g> Segment<'g> {
    /// Buffers for stretches of up to `len` positions of `grid`'s lines, to keep within
    /// `limit` (the height's; each variable's follows from it).
    fn new(grid: &'g Grid, limit: f64, len: usize) -> Segment<'g> {
        let variables = grid
            .variables()
            .iter()
            .filter(|v| !v.unconstrained())
            .map(|v| VariableStretch {
                grid: &v.grid,
                bound: hair_tighter(v.cap(limit)),
                values: vec![0.0; len],
                cone: (0.0, 0.0),
            })
            .collect();
        Segment {
            grid,
            limit,
            z: vec![0.0; len],
            heights: vec![0.0; len],
            variables,
            reciprocals: (0..len).map(|k| 1.0 / k as f64).collect(),
            n: 0,
        }
    }

    /// Loads positions `span` of `line`.
    fn load(&mut self, lines: &Lines, line: usize, span: std::ops::RangeInclusive<usize>) {
        let values = self.grid.values();
        self.n = span.end() - span.start() + 1;
        for (k, p) in span.enumerate() {
            let i = lines.sample(line, p);
            let (x, y) = if lines.along_rows {
                (p, line)
            } else {
                (line, p)
            };
            self.z[k] = values[i];
            self.heights[k] = self.grid.vertex_height_at(i, x, y);
            for v in &mut self.variables {
                v.values[k] = v.grid.values()[i];
            }
        }
    }

    /// Calls `keep` with the interior positions, in order, of a polyline through the
    /// loaded stretch's vertices (both ends always in it) such that every sample lies
    /// within the bound of it, in every field: from each kept vertex, the furthest next
    /// one that a straight segment reaches with every sample between within the bound
    /// (tracked per field as the cone of slopes that keeps them all). Each vertex height
    /// must be within the limit of its sample.
    fn simplify(&mut self, mut keep: impl FnMut(usize)) {
        let (n, z, heights) = (self.n, &self.z[..self.n], &self.heights[..self.n]);
        let bound = hair_tighter(self.limit);
        let mut start = 0;
        while start + 2 < n {
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            for v in &mut self.variables {
                v.cone = (f64::NEG_INFINITY, f64::INFINITY);
            }
            let mut reach = start + 1;
            let zs = heights[start];
            for (end, &ze) in z.iter().enumerate().skip(start + 1) {
                let per_run = self.reciprocals[end - start];
                let slope = (heights[end] - zs) * per_run;
                let rise = ze - zs;
                let mut reaches = lo <= slope && slope <= hi;
                lo = lo.max((rise - bound) * per_run);
                hi = hi.min((rise + bound) * per_run);
                let mut empty = lo > hi;
                for v in &mut self.variables {
                    let (vs, ve) = (v.values[start], v.values[end]);
                    let slope = (ve - vs) * per_run;
                    let (lo, hi) = &mut v.cone;
                    reaches &= *lo <= slope && slope <= *hi;
                    *lo = lo.max((ve - vs - v.bound) * per_run);
                    *hi = hi.min((ve - vs + v.bound) * per_run);
                    empty |= *lo > *hi;
                }
                if reaches {
                    reach = end;
                }
                if empty {
                    break;
                }
            }
            if reach + 1 >= n {
                return;
            }
            keep(reach);
            start = reach;
        }
    }
}

/// A hair tighter than `bound`, so that rounding in the 1-D pass rarely admits a segment
/// the exact measurement then refuses.
fn hair_tighter(bound: f64) -> f64 {
    bound * (1.0 - 1e-9)
}

/// Triangles reordered by the row of their first sample index (stable within a row): the
/// mesh's slots then follow the grid's row-major order, as its removal sweeps do, instead
/// of striding across rows along columns.
fn in_row_order(
    grid: &Grid,
    corners: Vec<[u32; 3]>,
    bounds: Vec<CompactBound>,
) -> (Vec<[u32; 3]>, Vec<CompactBound>) {
    let width = grid.width();
    let row = |c: &[u32; 3]| (c.iter().min().expect("three corners") / width) as usize;
    let mut starts = vec![0usize; grid.height() as usize + 1];
    for c in &corners {
        starts[row(c) + 1] += 1;
    }
    for r in 1..starts.len() {
        starts[r] += starts[r - 1];
    }
    let mut order = vec![0u32; corners.len()];
    for (t, c) in corners.iter().enumerate() {
        let r = row(c);
        order[starts[r]] = t as u32;
        starts[r] += 1;
    }
    let sorted_corners = order.iter().map(|&t| corners[t as usize]).collect();
    let sorted_bounds = order.iter().map(|&t| bounds[t as usize]).collect();
    (sorted_corners, sorted_bounds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edge_limit::NO_EDGE_LIMIT;
    use crate::Variable;
    use tinsmith_georef::Samples;

    fn kept_interior(z: &[f64], limit: f64) -> Vec<usize> {
        let grid = Grid::new(z.len() as u32, 1, z.to_vec()).unwrap();
        let mut segment = Segment::new(&grid, limit, z.len());
        segment.load(&Lines::new(&grid, true), 0, 0..=z.len() - 1);
        let mut kept = Vec::new();
        segment.simplify(|p| kept.push(p));
        kept
    }

    #[test]
    fn simplify_keeps_only_what_the_bound_needs() {
        let tent = [0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0];
        assert_eq!(kept_interior(&tent, 0.1), vec![3]);
        assert_eq!(kept_interior(&tent, 1.6), vec![4]);
        assert!(kept_interior(&tent, 3.5).is_empty());
        let line: Vec<f64> = (0..50).map(|x| 0.5 * x as f64).collect();
        assert!(kept_interior(&line, 1e-9).is_empty());
        let zigzag = [0.0, 1.0, 0.0, 1.0, 0.0];
        assert_eq!(kept_interior(&zigzag, 0.4), vec![1, 2, 3]);
    }

    #[test]
    fn the_estimate_of_every_line_is_the_count() {
        let values = (0..37 * 23)
            .map(|i| {
                let (x, y) = ((i % 37) as f64, (i / 37) as f64);
                5.0 * (x * 0.4).sin() * (y * 0.3).cos() + 0.02 * x * y
            })
            .collect();
        let g = Grid::new(37, 23, values).unwrap();
        for full_border in [false, true] {
            for limit in [0.05, 0.5, 3.0] {
                let count = |along_rows| {
                    kept_samples(&g, Lines::new(&g, along_rows), limit, full_border, &|| {})
                        .positions
                        .len()
                };
                let (rows, columns) = (count(true), count(false));
                assert_eq!(estimated_kept(&g, limit, full_border, 1), rows.min(columns));
                for along_rows in [true, false] {
                    let estimate =
                        estimated_kept_along(&g, Lines::new(&g, along_rows), limit, full_border, 1);
                    assert_eq!(estimate, count(along_rows));
                }
                let rough = estimated_kept(&g, limit, full_border, 4) as f64;
                let exact = rows.min(columns) as f64;
                assert!((rough / exact - 1.0).abs() < 0.25, "{rough} {exact}");
            }
        }
    }

    /// Sum of doubled areas, and that every triangle's bounding box has only valid cells.
    fn doubled_area_in_domain(grid: &Grid, corners: &[[u32; 3]]) -> i64 {
        let w = grid.width();
        let p = |i: u32| Point {
            x: i64::from(i % w),
            y: i64::from(i / w),
            z: 0.0,
        };
        let mut area = 0;
        for c in corners {
            let [a, b, d] = c.map(p);
            let o = orient(&a, &b, &d);
            assert!(o > 0, "{c:?} not counter-clockwise");
            area += o;
            let (x0, x1) = (a.x.min(b.x).min(d.x), a.x.max(b.x).max(d.x));
            let (y0, y1) = (a.y.min(b.y).min(d.y), a.y.max(b.y).max(d.y));
            for y in y0..y1 {
                for x in x0..x1 {
                    assert!(grid.cell_is_valid(x as usize, y as usize), "{c:?}");
                }
            }
        }
        area
    }

    #[test]
    fn a_plane_zips_into_two_triangles_per_strip() {
        let values = (0..20)
            .map(|i| (i % 5) as f64 + 2.0 * (i / 5) as f64)
            .collect();
        let grid = Grid::new(5, 4, values).unwrap();
        let plan = StripPlan::new(&grid, 0.25, false, &|| {}).unwrap();
        assert_eq!(plan.triangle_count(), 6);
        let (corners, bounds) = plan.triangles(&NO_EDGE_LIMIT, &|| {}).unwrap();
        assert_eq!(corners.len(), 6);
        assert!(bounds.iter().all(|b| ErrorBound::from(*b).max() == 0.0));
        assert_eq!(doubled_area_in_domain(&grid, &corners), 2 * 4 * 3);
    }

    #[test]
    fn every_variable_is_kept_within_its_bound_by_the_lines() {
        // A flat height and a variable with a bump the height cannot see: the lines, along
        // rows or columns, must keep the bump's samples, so that every zipped triangle
        // passes the exact check of every variable (without them the plan's triangles
        // are refused).
        let (w, h) = (19u32, 17u32);
        let height = Samples::new(w, h, vec![3.0; (w * h) as usize]).unwrap();
        let bump: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = (f64::from(i % w), f64::from(i / w));
                10.0 * (-((x - 9.0).powi(2) + (y - 8.0).powi(2)) / 8.0).exp()
            })
            .collect();
        let variable = Variable::new(Samples::new(w, h, bump).unwrap(), 0.5).unwrap();
        let grid = Grid::with_variables(height.clone(), vec![variable])
            .unwrap()
            .with_height_limit(1.0);
        let plain_grid = Grid::from_samples(height);
        let plain = StripPlan::new(&plain_grid, 1.0, false, &|| {}).unwrap();
        let plan = StripPlan::new(&grid, 1.0, false, &|| {}).unwrap();
        assert!(plan.kept_count() > plain.kept_count());
        let (corners, bounds) = plan
            .triangles(&NO_EDGE_LIMIT, &|| {})
            .expect("every triangle passes");
        assert_eq!(corners.len(), plan.triangle_count());
        assert!(bounds.iter().all(|b| ErrorBound::from(*b).max() <= 1.0));
        assert_eq!(
            doubled_area_in_domain(&grid, &corners),
            2 * grid.valid_cell_count() as i64
        );
    }

    #[test]
    fn strips_cover_exactly_the_valid_cells_within_the_bound() {
        let (w, h) = (23u32, 17u32);
        let mut values: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = (f64::from(i % w), f64::from(i / w));
                (x * 0.7).sin() * 5.0 + (y * 0.3).cos() * 3.0 + x * y * 0.01
            })
            .collect();
        for i in [40, 41, 100, 250, 251, 252, 300] {
            values[i] = f64::NAN;
        }
        let grid = Grid::new(w, h, values).unwrap();
        for full_border in [false, true] {
            for limit in [0.3, 2.0, 50.0] {
                let plan = StripPlan::new(&grid, limit, full_border, &|| {}).unwrap();
                let (corners, bounds) = plan.triangles(&NO_EDGE_LIMIT, &|| {}).unwrap();
                assert_eq!(corners.len(), plan.triangle_count());
                assert!(bounds.iter().all(|b| ErrorBound::from(*b).max() <= limit));
                let area = doubled_area_in_domain(&grid, &corners);
                assert_eq!(area, 2 * grid.valid_cell_count() as i64, "at {limit}");
                if full_border {
                    // Triangles touching the grid's outer rows or columns are half cells.
                    for c in &corners {
                        let on_border = c.iter().any(|&i| {
                            let (x, y) = (i % w, i / w);
                            x == 0 || y == 0 || x == w - 1 || y == h - 1
                        });
                        let [a, b, d] = c.map(|i| Point {
                            x: i64::from(i % w),
                            y: i64::from(i / w),
                            z: 0.0,
                        });
                        assert!(!on_border || orient(&a, &b, &d) == 1, "{c:?}");
                    }
                }
            }
        }
    }
}
