//! One level's lattice, a window of rows at a time: which tiles and lattice points the level
//! covers, the rows currently held, what a tile reads from them (its grid, its edges with
//! their halo, its normals), and the next coarser level's rows filtered from them.

use std::ops::Range;

use crate::quantized_mesh::surface_normal;
use rayon::prelude::*;
use tinsmith_raster::GeoLattice;

use crate::tms::{Scheme, TileRect, Tiling};
use tinsmith_tiling::EdgeProfile;

/// The binomial taps of the downsampling filter, by offset in finer lattice steps.
const TAPS: [(i64, f64); 5] = [(-2, 1.0), (-1, 4.0), (0, 6.0), (1, 4.0), (2, 1.0)];

/// The samples of one level on its lattice, over whole tiles: global lattice column
/// `cells tx0 + i`, row `cells ty0 + j` (row 0 the southernmost), NaN where there is no data.
///
/// A level whose tiles go all the way round the globe ([`LevelRows::wraps`]) is periodic:
/// its last column is its first one a turn east (and holds the same samples), and
/// whatever reads past one side of it reads the other, so the tiles either side of the
/// seam see the same edge, and coarser levels filter across it.
///
/// Rows arrive in increasing order ([`LevelRows::push`]) and leave from the bottom
/// ([`LevelRows::drop_below`]); only rows `first..end()` are held. Every accessor takes
/// level-wide coordinates and treats the level's own border (row or column outside
/// `0..height`, `0..width`) exactly as the whole raster did, so a tile reads the same
/// samples, edges and normals whatever else is held.
pub(super) struct LevelRows {
    /// The pyramid's tiling.
    pub(super) tiling: Scheme,
    pub(super) level: u8,
    /// First tile column and TMS row covered.
    pub(super) tx0: u32,
    pub(super) ty0: u32,
    /// Tiles covered.
    pub(super) tiles_x: u32,
    pub(super) tiles_y: u32,
    /// Lattice columns and rows of the whole level.
    pub(super) width: usize,
    /// Whether the tiles go all the way round (`2^(level+1)` columns).
    wraps: bool,
    pub(super) height: usize,
    /// The first row held.
    first: usize,
    /// Rows `first..end()`, row-major.
    values: Vec<f32>,
    /// The samples anything built from this level reads, when not all of them.
    reach: Option<Reach>,
    /// The height of the globe beyond the raster (NaN: none), which the coarser level's
    /// filter reads past this level's lattice (see [`LevelRows::filled_with`]).
    outside: f32,
}

/// The part of a level that the tiles built from it depend on (see
/// [`LevelRows::within`]): its samples elsewhere are never made and stay NaN.
#[derive(Debug, Clone)]
pub(super) struct Reach {
    /// Rows (local) in reach.
    pub(super) rows: Range<usize>,
    /// Per column (local), whether it is in reach.
    pub(super) columns: Vec<bool>,
}

impl Reach {
    /// The runs of consecutive columns in reach, west to east.
    pub(super) fn column_runs(&self) -> Vec<Range<usize>> {
        let mut runs: Vec<Range<usize>> = Vec::new();
        for (i, _) in self.columns.iter().enumerate().filter(|(_, &c)| c) {
            match runs.last_mut() {
                Some(run) if run.end == i => run.end = i + 1,
                _ => runs.push(i..i + 1),
            }
        }
        runs
    }
}

impl LevelRows {
    /// The level's lattice over the tiles of `rect`, holding no rows yet. Whatever lies
    /// outside `rect` counts as the level's border (no data).
    pub(super) fn new(rect: TileRect) -> LevelRows {
        LevelRows {
            tiling: rect.tiling,
            level: rect.level,
            tx0: rect.x0,
            ty0: rect.y0,
            tiles_x: rect.width,
            tiles_y: rect.height,
            width: rect.width as usize * rect.tiling.cells as usize + 1,
            height: rect.height as usize * rect.tiling.cells as usize + 1,
            wraps: rect.wraps(),
            first: 0,
            values: Vec::new(),
            reach: None,
            outside: f32::NAN,
        }
    }

    /// The same level on a globe filled with `outside` beyond the raster: the sampler
    /// gives it to points outside the raster, and the filter reads it past the level's
    /// lattice (which holds the whole raster), so a coarser level is the filter of the
    /// whole filled globe. NaN: no fill.
    pub(super) fn filled_with(mut self, outside: f32) -> LevelRows {
        self.outside = outside;
        self
    }

    /// The same level, of which only `reach` is made: the finest level is sampled there
    /// alone and coarser levels filter there alone, NaN elsewhere. Whatever reads only
    /// samples in reach gets the same values as from the whole level, provided each
    /// coarser level's reach is filtered from samples in this one's.
    ///
    /// # Panics
    /// When `reach` does not fit the level.
    pub(super) fn within(mut self, reach: Reach) -> LevelRows {
        assert!(reach.columns.len() == self.width && reach.rows.end <= self.height);
        self.reach = Some(reach);
        self
    }

    /// What is made of the level: `None` for all of it.
    pub(super) fn reach(&self) -> Option<&Reach> {
        self.reach.as_ref()
    }

    /// Tile `x`, `y` of `level` alone, at height 0 everywhere (the ellipsoid), every row
    /// held: a root tile CesiumJS expects that the raster does not reach (`--metadata`).
    pub(super) fn flat_tile(tiling: Scheme, level: u8, x: u32, y: u32) -> LevelRows {
        let side = tiling.cells as usize + 1;
        LevelRows {
            tiling,
            level,
            tx0: x,
            ty0: y,
            tiles_x: 1,
            tiles_y: 1,
            width: side,
            height: side,
            wraps: false,
            first: 0,
            values: vec![0.0; side * side],
            reach: None,
            outside: f32::NAN,
        }
    }

    /// Cells along each side of a tile's lattice.
    fn cells(&self) -> usize {
        self.tiling.cells as usize
    }

    /// One past the last row held: the number of rows pushed so far.
    pub(super) fn end(&self) -> usize {
        self.first + self.values.len() / self.width
    }

    /// Whether every row of the level has been pushed.
    pub(super) fn complete(&self) -> bool {
        self.end() == self.height
    }

    /// Lattice rows `rows`, columns `columns` (level-wide), as a window of the global
    /// lattice of the level (column 0 at -180°, row 0 at the tiling's southern edge, see
    /// [`Tiling::lattice`]): each point's position depends on its global indices only,
    /// whatever the window.
    pub(super) fn lattice(&self, rows: Range<usize>, columns: Range<usize>) -> GeoLattice {
        let cells = u64::from(self.tiling.cells);
        self.tiling.lattice(
            self.level,
            u64::from(self.tx0) * cells + columns.start as u64,
            u64::from(self.ty0) * cells + rows.start as u64,
            columns.len() as u32,
            rows.len() as u32,
        )
    }

    /// The latitude of row `j` (level-wide, may lie outside the level).
    fn row_latitude(&self, j: i64) -> f64 {
        let row = i64::from(self.ty0) * i64::from(self.tiling.cells) + j;
        self.tiling.row_latitude(self.level, row)
    }

    /// Appends whole rows after the last one held.
    ///
    /// # Panics
    /// When `rows` is not a whole number of rows or goes past the level's last row: the
    /// stream makes exactly the rows of the level, in order.
    pub(super) fn push(&mut self, rows: &[f32]) {
        assert!(
            rows.len().is_multiple_of(self.width)
                && self.end() + rows.len() / self.width <= self.height,
            "level {}: {} samples do not continue rows 0..{} of {} x {}",
            self.level,
            rows.len(),
            self.end(),
            self.width,
            self.height
        );
        self.values.extend_from_slice(rows);
        if self.wraps {
            let start = self.values.len() - rows.len();
            for row in self.values[start..].chunks_exact_mut(self.width) {
                row[self.width - 1] = row[0];
            }
        }
    }

    /// Column `i` (which may lie outside the level), or `None` outside a level that does
    /// not wrap; around a level that wraps, the column a whole turn away inside it.
    fn column(&self, i: i64) -> Option<usize> {
        if self.wraps {
            Some(i.rem_euclid(self.width as i64 - 1) as usize)
        } else {
            (i >= 0 && i < self.width as i64).then_some(i as usize)
        }
    }

    /// Drops the rows below `row` (all held rows if `row` is beyond them).
    pub(super) fn drop_below(&mut self, row: usize) {
        let row = row.min(self.end());
        if row > self.first {
            self.values.drain(..(row - self.first) * self.width);
            self.first = row;
        }
    }

    /// Row `j`, or `None` outside the level.
    ///
    /// # Panics
    /// When `j` is in the level but not held: the stream keeps every row a reader needs.
    fn row(&self, j: i64) -> Option<&[f32]> {
        if j < 0 || j >= self.height as i64 {
            return None;
        }
        let j = j as usize;
        assert!(
            j >= self.first && j < self.end(),
            "level {}: row {j} is needed but rows {}..{} are held",
            self.level,
            self.first,
            self.end()
        );
        let start = (j - self.first) * self.width;
        Some(&self.values[start..start + self.width])
    }

    pub(super) fn at(&self, i: usize, j: usize) -> f64 {
        let row = self.row(j as i64).expect("a sample inside the level");
        f64::from(row[i])
    }

    /// The tile rows (local, from 0) whose rows and one-row halo are all held or past the
    /// level's border: `0..ready_tile_rows()` minus those already handed out.
    pub(super) fn ready_tile_rows(&self) -> u32 {
        let end = self.end();
        (0..self.tiles_y)
            .take_while(|&t| ((t as usize + 1) * self.cells() + 2).min(self.height) <= end)
            .count() as u32
    }

    /// The first row that tile row `t` (local) reads: its southern edge less the halo;
    /// the level's height once every tile row is done.
    pub(super) fn first_row_of_tile_row(&self, t: u32) -> usize {
        if t >= self.tiles_y {
            self.height
        } else {
            (t as usize * self.cells()).saturating_sub(1)
        }
    }

    /// Sample (0, 0) of tile `x`, `y` (global tile indices) in level coordinates.
    pub(super) fn tile_origin(&self, x: u32, y: u32) -> (usize, usize) {
        (
            (x - self.tx0) as usize * self.cells(),
            (y - self.ty0) as usize * self.cells(),
        )
    }

    /// The `(cells + 1)^2` samples of tile `x`, `y`, row-major from the south-west.
    pub(super) fn tile_values(&self, x: u32, y: u32) -> Vec<f64> {
        let (i0, j0) = self.tile_origin(x, y);
        let mut values = Vec::with_capacity((self.cells() + 1) * (self.cells() + 1));
        for j in j0..=j0 + self.cells() {
            let row = self.row(j as i64).expect("a tile row inside the level");
            values.extend(row[i0..=i0 + self.cells()].iter().map(|&v| f64::from(v)));
        }
        values
    }

    /// Feeds `hash` everything a tile `x`, `y` is built from: its samples and a ring of one
    /// around them (edges and normals read it), each as its f32 bits, NaN as one value,
    /// and a marker for a sample outside the level. Two tiles hashed the same are built
    /// the same (with the same options and metadata).
    pub(super) fn hash_tile_window(&self, x: u32, y: u32, hash: &mut impl sha2::Digest) {
        const OUTSIDE: u32 = 0xffff_fffe;
        let (i0, j0) = self.tile_origin(x, y);
        let (i0, j0) = (i0 as i64, j0 as i64);
        let mut bytes = Vec::with_capacity((self.cells() + 3) * 4);
        for j in j0 - 1..=j0 + self.cells() as i64 + 1 {
            bytes.clear();
            let row = self.row(j);
            let (first, last) = (i0 - 1, i0 + self.cells() as i64 + 1);
            if let Some(r) = row.filter(|_| first >= 0 && last + 1 < self.width as i64) {
                // Every column inside the level, at its own index (also round a level that
                // wraps: its last column, which repeats the first, is not reached).
                for &v in &r[first as usize..=last as usize] {
                    let bits = if v.is_nan() { f32::NAN } else { v }.to_bits();
                    bytes.extend_from_slice(&bits.to_le_bytes());
                }
                hash.update(&bytes);
                continue;
            }
            for i in first..=last {
                let bits = match (row, self.column(i)) {
                    (Some(r), Some(c)) if r[c].is_nan() => f32::NAN.to_bits(),
                    (Some(r), Some(c)) => r[c].to_bits(),
                    _ => OUTSIDE,
                };
                bytes.extend_from_slice(&bits.to_le_bytes());
            }
            hash.update(&bytes);
        }
    }

    /// Whether the cell with lower-left sample (i, j) lies in the level (round it, when
    /// it wraps) and has four valid corners.
    pub(super) fn cell_valid(&self, i: i64, j: i64) -> bool {
        let Some(i) = self.column(i).filter(|&i| i + 1 < self.width) else {
            return false;
        };
        if j < 0 || j + 1 >= self.height as i64 {
            return false;
        }
        let j = j as usize;
        [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
            .iter()
            .all(|&(a, b)| self.at(a, b).is_finite())
    }

    /// The edge from sample (i, j) along +x (`horizontal`) or +y, `cells` steps,
    /// as both tiles beside it see it. Reads rows `j - 1 ..= j + 1` of a horizontal edge,
    /// `j ..= j + TILE_CELLS` of a vertical one.
    pub(super) fn edge(&self, i: usize, j: usize, horizontal: bool) -> EdgeProfile {
        let n = self.cells();
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
                // The cells on both sides of the step; a side outside the level is the
                // level's outer border, where no tile has data.
                let (side1, side2) = if horizontal {
                    ((a, b - 1), (a, b))
                } else {
                    ((a - 1, b), (a, b))
                };
                let inside = |(x, y): (i64, i64)| {
                    self.column(x).is_some_and(|x| x + 1 < self.width)
                        && y >= 0
                        && y + 1 < self.height as i64
                };
                [side1, side2]
                    .iter()
                    .all(|&c| !inside(c) || self.cell_valid(c.0, c.1))
            })
            .collect();
        EdgeProfile::new(values, open)
    }

    /// Unit ECEF normal at sample (i, j) from central differences of the level's samples
    /// (one-sided at nodata or the level's border): the same for every tile that has the
    /// sample, so normals are continuous across tile edges. Reads rows `j - 1 ..= j + 1`.
    /// On a pole's row, where every sample is the same point, the east-west difference is
    /// left out: its spacing is zero, and it made normals up to 90 degrees off vertical.
    pub(super) fn normal(&self, i: usize, j: usize, lon: f64, lat: f64) -> [f64; 3] {
        let d = self.tiling.step(self.level).to_radians();
        let z = self.at(i, j);
        let sample = |a: i64, b: i64| -> Option<f64> {
            let a = self.column(a)?;
            if b < 0 || b >= self.height as i64 {
                return None;
            }
            Some(self.at(a, b as usize)).filter(|v| v.is_finite())
        };
        // Spacings to the samples before and after.
        let slope = |lo: Option<f64>, hi: Option<f64>, (before, after): (f64, f64)| match (lo, hi) {
            (Some(a), Some(b)) => (b - a) / (before + after),
            (None, Some(b)) => (b - z) / after,
            (Some(a), None) => (z - a) / before,
            (None, None) => 0.0,
        };
        let (ii, jj) = (i as i64, j as i64);
        let dx = crate::quantized_mesh::WGS84_A * d * lat.to_radians().cos().max(1e-6);
        let dy = match self.tiling.tiling {
            Tiling::Geographic => {
                let dy = crate::quantized_mesh::WGS84_A * d;
                (dy, dy)
            }
            // Rows are evenly spaced inside a tile only: the spacings either side differ
            // on a tile's edge.
            Tiling::Mercator => {
                let spacing = |a: i64, b: i64| {
                    crate::quantized_mesh::WGS84_A
                        * (self.row_latitude(b) - self.row_latitude(a)).to_radians()
                };
                (spacing(jj - 1, jj), spacing(jj, jj + 1))
            }
        };
        let at_pole = lat.abs() >= 90.0 - 1e-9;
        let ge = if at_pole {
            0.0
        } else {
            slope(sample(ii - 1, jj), sample(ii + 1, jj), (dx, dx))
        };
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

    /// This level's row (local) that `coarser`'s row 0 is centred on: coarser row `J` is
    /// centred on row `2 J + offset` here (`offset` is 0 or -cells).
    fn offset_to(&self, coarser: &LevelRows) -> i64 {
        let cells = i64::from(self.tiling.cells);
        2 * i64::from(coarser.ty0) * cells - i64::from(self.ty0) * cells
    }

    /// Where coarser row `J` (local) reads this level's rows, one entry per vertical tap
    /// of the filter: a row here (local; outside the level it reads the globe beyond) and
    /// the weight of the row after it, `None` past the tiling's edge. Geographic: rows
    /// `2 J + offset - 2 ..= 2 J + offset + 2`, weight 0. Web Mercator: the rows of a
    /// lattice half as fine as the coarser one's (`2 cells` rows a coarser tile,
    /// evenly spaced in latitude), around `2 J`, each placed in latitude among this
    /// level's rows (whose tiles split the coarser tile at its Web Mercator middle, not its
    /// latitude middle) and interpolated linearly in latitude between the two around it.
    fn vertical_taps(&self, coarser: &LevelRows, row: usize) -> [Option<(i64, f64)>; 5] {
        match self.tiling.tiling {
            Tiling::Geographic => {
                let centre = 2 * row as i64 + self.offset_to(coarser);
                TAPS.map(|(dy, _)| Some((centre + dy, 0.0)))
            }
            Tiling::Mercator => {
                let cells = i64::from(self.tiling.cells);
                let tiles = 1u64 << coarser.level;
                let half = 2 * (i64::from(coarser.ty0) * cells + row as i64);
                let first = i64::from(self.ty0) * cells;
                TAPS.map(|(dy, _)| {
                    let h = half + dy;
                    if h < 0 || h > 2 * cells * tiles as i64 {
                        return None;
                    }
                    let half_lattice = tinsmith_raster::GeoLattice {
                        latitudes: tinsmith_raster::Latitudes::WebMercatorTiles {
                            cells: 2 * self.tiling.cells,
                            tiles,
                        },
                        first_row: h as u64,
                        ..self.tiling.lattice(coarser.level, 0, 0, 1, 1)
                    };
                    let position = self.tiling.row_position(self.level, half_lattice.lat(0));
                    let below = position.floor();
                    Some((below as i64 - first, position - below))
                })
            }
        }
    }

    /// The lowest and highest rows here (local) that coarser row `J` reads.
    fn rows_read(&self, coarser: &LevelRows, row: usize) -> (i64, i64) {
        let taps = self.vertical_taps(coarser, row);
        let mut range = (i64::MAX, i64::MIN);
        for (r, w) in taps.into_iter().flatten() {
            range = (range.0.min(r), range.1.max(r + i64::from(w > 0.0)));
        }
        range
    }

    /// One past the last row of `coarser` that can be made from the rows pushed here so
    /// far: row `J` reads the rows [`LevelRows::vertical_taps`] names (those outside this
    /// level count as nodata).
    pub(super) fn coarser_rows_ready(&self, coarser: &LevelRows) -> usize {
        if self.complete() {
            return coarser.height;
        }
        if self.tiling.tiling == Tiling::Geographic {
            // 2 J + offset + 2 < end, so J <= (end - offset - 3) / 2.
            let limit = self.end() as i64 - self.offset_to(coarser) - 3;
            if limit < 0 {
                return 0;
            }
            return (limit as usize / 2 + 1).min(coarser.height);
        }
        let mut ready = coarser.end();
        while ready < coarser.height && self.rows_read(coarser, ready).1 < self.end() as i64 {
            ready += 1;
        }
        ready
    }

    /// The first row here that `coarser`'s next row (its `end()`) reads.
    pub(super) fn first_row_for(&self, coarser: &LevelRows) -> usize {
        if coarser.complete() {
            return self.height;
        }
        self.rows_read(coarser, coarser.end()).0.max(0) as usize
    }

    /// Rows `rows` of the next coarser level: lattice point (X, Y) there is this level's
    /// (2X, 2Y), low-pass filtered with the binomial [1 4 6 4 1] x [1 4 6 4 1] kernel over
    /// the valid samples here; nodata only where all 25 are. Columns are matched round
    /// the globe: a coarser level that wraps, or one that starts west of this one, reads
    /// the samples a whole turn away where this level has them. The domain so grows by at most
    /// one coarse sample per level, which keeps small inputs visible at coarse levels.
    /// Rows are filtered in parallel; each sample's sum runs in the same order whatever
    /// the rows held, so the result depends only on the level's samples. Only the
    /// coarser level's reach ([`LevelRows::within`]) is filtered; the rest is NaN.
    ///
    /// # Panics
    /// When a row the filter reads is not held (see [`LevelRows::coarser_rows_ready`]).
    pub(super) fn coarser_rows(&self, coarser: &LevelRows, rows: Range<usize>) -> Vec<f32> {
        let cells = i64::from(self.tiling.cells);
        let fx0 = i64::from(self.tx0) * cells;
        let fy0 = i64::from(self.ty0) * cells;
        let cx0 = i64::from(coarser.tx0) * cells;
        let cy0 = i64::from(coarser.ty0) * cells;
        let width = coarser.width;
        // Lattice columns in a whole turn of this level.
        let turn = self.tiling.columns(self.level) as i64 * cells;
        // The column here of each tap of each coarse column, `None` outside this level:
        // the same for every row, so worked out once.
        let columns: Vec<[Option<usize>; 5]> = (0..width)
            .map(|i| {
                let gx = 2 * (cx0 + i as i64);
                TAPS.map(|(dx, _)| {
                    let i = (gx + dx - fx0).rem_euclid(turn);
                    (i < self.width as i64).then_some(i as usize)
                })
            })
            .collect();
        let all = vec![true; width];
        let (reach_rows, reach_columns) = match &coarser.reach {
            Some(reach) => (reach.rows.clone(), &reach.columns),
            None => (0..coarser.height, &all),
        };
        let mut out = vec![f32::NAN; width * rows.len()];
        if self.tiling.tiling == Tiling::Mercator {
            self.resampled_coarser_rows(coarser, rows, &columns, &mut out);
            return out;
        }
        out.par_chunks_mut(width).enumerate().for_each(|(k, row)| {
            if !reach_rows.contains(&(rows.start + k)) {
                return;
            }
            let gy = 2 * (cy0 + (rows.start + k) as i64);
            let fine_rows = TAPS.map(|(dy, _)| self.row(gy + dy - fy0));
            // Every tap row inside the level: the taps of a column with all five columns
            // inside are read directly, summed in the same order as below.
            let inner_rows: Option<[&[f32]; 5]> = if fine_rows.iter().all(Option::is_some) {
                Some(fine_rows.map(|r| r.expect("checked")))
            } else {
                None
            };
            for ((slot, taps), _) in row
                .iter_mut()
                .zip(&columns)
                .zip(reach_columns)
                .filter(|(_, &in_reach)| in_reach)
            {
                if let (Some(lines), [Some(c0), Some(c1), Some(c2), Some(c3), Some(c4)]) =
                    (&inner_rows, *taps)
                {
                    let cs = [c0, c1, c2, c3, c4];
                    let (mut sum, mut weight) = (0.0f64, 0.0f64);
                    for (r, (_, wy)) in lines.iter().zip(TAPS) {
                        for (&c, (_, wx)) in cs.iter().zip(TAPS) {
                            let v = r[c];
                            if v.is_finite() {
                                sum += wx * wy * f64::from(v);
                                weight += wx * wy;
                            }
                        }
                    }
                    if weight > 0.0 {
                        *slot = (sum / weight) as f32;
                    }
                    continue;
                }
                let (mut sum, mut weight) = (0.0f64, 0.0f64);
                for (r, (_, wy)) in fine_rows.iter().zip(TAPS) {
                    for (column, (_, wx)) in taps.iter().zip(TAPS) {
                        // Past the lattice: the globe beyond the raster, if filled.
                        let v = match (r, column) {
                            (Some(r), Some(c)) => r[*c],
                            _ => self.outside,
                        };
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

    /// [`LevelRows::coarser_rows`] of a Web Mercator level: the filter over rows resampled
    /// in latitude ([`LevelRows::vertical_taps`]); a resampled sample between a valid and
    /// a nodata one is the valid one, so the domain grows as the geographic filter's does.
    /// `columns` are each coarse column's taps here.
    fn resampled_coarser_rows(
        &self,
        coarser: &LevelRows,
        rows: Range<usize>,
        columns: &[[Option<usize>; 5]],
        out: &mut [f32],
    ) {
        let width = coarser.width;
        let all = vec![true; width];
        let (reach_rows, reach_columns) = match &coarser.reach {
            Some(reach) => (reach.rows.clone(), &reach.columns),
            None => (0..coarser.height, &all),
        };
        let outside = f64::from(self.outside);
        out.par_chunks_mut(width).enumerate().for_each(|(k, row)| {
            if !reach_rows.contains(&(rows.start + k)) {
                return;
            }
            let lines = self
                .vertical_taps(coarser, rows.start + k)
                .map(|tap| tap.map(|(r, w)| (self.row(r), (w > 0.0).then(|| self.row(r + 1)), w)));
            for ((slot, taps), _) in row
                .iter_mut()
                .zip(columns)
                .zip(reach_columns)
                .filter(|(_, &in_reach)| in_reach)
            {
                let (mut sum, mut weight) = (0.0f64, 0.0f64);
                for (line, (_, wy)) in lines.iter().zip(TAPS) {
                    for (column, (_, wx)) in taps.iter().zip(TAPS) {
                        let v = match (line, column) {
                            (None, _) => f64::NAN,
                            (Some((below, above, w)), Some(c)) => {
                                let at =
                                    |r: &Option<&[f32]>| r.map_or(outside, |r| f64::from(r[*c]));
                                let a = at(below);
                                match above {
                                    None => a,
                                    Some(above) => {
                                        let b = at(above);
                                        match (a.is_finite(), b.is_finite()) {
                                            (true, true) => a + (b - a) * w,
                                            (true, false) => a,
                                            _ => b,
                                        }
                                    }
                                }
                            }
                            (Some(_), None) => outside,
                        };
                        if v.is_finite() {
                            sum += wx * wy * v;
                            weight += wx * wy;
                        }
                    }
                }
                if weight > 0.0 {
                    *slot = (sum / weight) as f32;
                }
            }
        });
    }
}
