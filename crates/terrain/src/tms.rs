//! The tilings (TMS geographic, EPSG:4326 with two level-0 tiles; Web Mercator, EPSG:3857
//! with one) and each tile's lattice of `cells` cells a side ([`LATTICE_CELLS`]).

use crate::pyramid::MAX_LEVEL;
use crate::quantized_mesh::{GeoRectangle, QUANTIZED_MAX};
use tinsmith_raster::{web_mercator_latitude, web_mercator_y, GeoBounds, GeoLattice, Latitudes};

/// How a pyramid's tiles divide the globe (`layer.json`'s `projection`). Part of every
/// tile's identity: a pyramid, its shards and its updates have one tiling.
///
/// Either way a tile's lattice has `cells + 1` columns evenly spaced in longitude and
/// as many rows evenly spaced in latitude between the tile's southern and northern edges,
/// which is how CesiumJS places a quantized-mesh vertex (`u`, `v` linear in longitude and
/// latitude across the tile's rectangle), so the surface it draws is linear in longitude
/// and latitude inside each triangle, as the lattice the bound is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Tiling {
    /// EPSG:4326: 2 x 1 tiles at level 0, each level's tiles 180 / 2^level degrees square.
    #[default]
    Geographic,
    /// EPSG:3857 (Web Mercator, CesiumJS's `WebMercatorTilingScheme`): 1 x 1 tile at level
    /// 0 covering latitudes up to about ±85.0511°, each level splitting a tile at its
    /// middle in longitude and in Web Mercator y (not in latitude). Rows stay evenly
    /// spaced in latitude inside each tile, so a tile's rows are not every other row of
    /// the finer level's.
    Mercator,
}

impl Tiling {
    /// `layer.json`'s `projection`.
    pub fn projection(self) -> &'static str {
        match self {
            Tiling::Geographic => "EPSG:4326",
            Tiling::Mercator => "EPSG:3857",
        }
    }

    /// The option's name (`--tiling`).
    pub fn name(self) -> &'static str {
        match self {
            Tiling::Geographic => "geographic",
            Tiling::Mercator => "mercator",
        }
    }

    /// Tile columns of level `z`: a whole turn of longitude.
    pub fn columns(self, z: u8) -> u64 {
        match self {
            Tiling::Geographic => 2u64 << z,
            Tiling::Mercator => 1u64 << z,
        }
    }

    /// The southernmost and northernmost latitudes tiles reach.
    pub fn latitude_range(self) -> [f64; 2] {
        match self {
            Tiling::Geographic => [-90.0, 90.0],
            Tiling::Mercator => [web_mercator_latitude(0.0), web_mercator_latitude(1.0)],
        }
    }

    /// Lattice spacing of a level of tiles of `cells` cells a side in longitude, degrees
    /// (in latitude too, geographic).
    pub(super) fn step(self, level: u8, cells: u32) -> f64 {
        match self {
            Tiling::Geographic => 180.0 / (f64::from(cells) * (1u64 << level) as f64),
            Tiling::Mercator => 360.0 / (f64::from(cells) * (1u64 << level) as f64),
        }
    }

    /// The tile column of lattice tile column `x` (which is past the last column across
    /// the antimeridian, see [`tile_range`]).
    pub(super) fn tile_column(self, z: u8, x: u32) -> u32 {
        (u64::from(x) % self.columns(z)) as u32
    }

    /// The tile rectangle `z/x/y` (TMS y, from the south) in degrees (east of 180 for
    /// `x` past the last column: the same tile a turn east). Web Mercator tiles' southern
    /// and northern edges are their Web Mercator y's latitudes, as CesiumJS's
    /// `WebMercatorTilingScheme.tileXYToRectangle` has them.
    pub fn tile_rectangle(self, z: u8, x: u32, y: u32) -> GeoRectangle {
        match self {
            Tiling::Geographic => tile_rectangle(z, x, y),
            Tiling::Mercator => {
                let n = (1u64 << z) as f64;
                let size = 360.0 / n;
                GeoRectangle {
                    west: -180.0 + f64::from(x) * size,
                    south: web_mercator_latitude(f64::from(y) / n),
                    east: -180.0 + f64::from(x + 1) * size,
                    north: web_mercator_latitude(f64::from(y + 1) / n),
                }
            }
        }
    }

    /// The latitude of global lattice row `row` of `level` (row 0 the southern edge of
    /// the tiling), as [`Tiling::lattice`] places it.
    pub(super) fn row_latitude(self, level: u8, cells: u32, row: i64) -> f64 {
        self.lattice(level, cells, 0, row.max(0) as u64, 1, 1)
            .lat(0)
    }

    /// Columns `first_column ..`, rows `first_row ..` (`width` x `height`) of the global
    /// lattice of `level` (column 0 at -180°, row 0 at the tiling's southern edge): each
    /// point's position depends on its global indices only, whatever the window.
    pub(super) fn lattice(
        self,
        level: u8,
        cells: u32,
        first_column: u64,
        first_row: u64,
        width: u32,
        height: u32,
    ) -> GeoLattice {
        let latitudes = match self {
            Tiling::Geographic => Latitudes::Uniform,
            Tiling::Mercator => Latitudes::WebMercatorTiles {
                cells,
                tiles: 1u64 << level,
            },
        };
        GeoLattice {
            west: -180.0,
            south: -90.0,
            step: self.step(level, cells),
            first_column,
            first_row,
            width,
            height,
            latitudes,
        }
    }

    /// Where latitude `lat` falls among the global lattice rows of `level`, as a
    /// fractional row index (rows spaced evenly in latitude inside each tile), clamped to
    /// the level's rows.
    pub(super) fn row_position(self, level: u8, cells: u32, lat: f64) -> f64 {
        let step = self.step(level, cells);
        let cells = f64::from(cells);
        let n = (1u64 << level) as f64;
        match self {
            Tiling::Geographic => ((lat + 90.0) / step).clamp(0.0, n * cells),
            Tiling::Mercator => {
                let tile = (web_mercator_y(lat) * n).floor().clamp(0.0, n - 1.0);
                let south = web_mercator_latitude(tile / n);
                let north = web_mercator_latitude((tile + 1.0) / n);
                (cells * (tile + (lat - south) / (north - south))).clamp(0.0, n * cells)
            }
        }
    }

    /// The most, in lattice rows of level `level + 1`, by which a row position of the
    /// half-spaced lattice of `level` (see [`crate::rows::LevelRows::coarser_rows`]) lies
    /// away from the same index of the finer level: 0 geographic (the lattices nest), and
    /// for Web Mercator a tile's latitude middle is away from its Web Mercator middle
    /// (about 122 rows at level 1, 79 at 2, 42 at 3, halving each level; measured with
    /// `tiles_split_at_their_mercator_middle_by_a_bounded_offset`), bounded here with room.
    pub(super) fn max_row_offset(self, level: u8) -> usize {
        match self {
            Tiling::Geographic => 0,
            Tiling::Mercator if level == 0 => 1,
            Tiling::Mercator => 2 + (340usize >> level.min(16)),
        }
    }
}

/// The cells a tile's lattice may have along each side, the default first: each tile
/// samples `(cells + 1)^2` lattice points. Both divide 32767 (= 7 x 31 x 151), so sample
/// `i` is at `u = i x 32767 / cells` exactly: decoded vertices sit exactly on their
/// source samples. A pyramid takes the one whose lattice at its own level (the first as
/// fine as the raster) is the least finer than the raster (see
/// [`lattice_cells`]).
pub const LATTICE_CELLS: [u32; 2] = [217, 151];

/// A tiling with the cells a side of its tiles' lattices: what places every lattice point
/// of a pyramid. Its methods are [`Tiling`]'s, with the cells given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scheme {
    /// How tiles divide the globe.
    pub tiling: Tiling,
    /// Cells along each side of a tile's lattice, one of [`LATTICE_CELLS`].
    pub cells: u32,
}

impl Scheme {
    /// Geographic tiles of the default lattice.
    pub const GEOGRAPHIC: Scheme = Scheme {
        tiling: Tiling::Geographic,
        cells: LATTICE_CELLS[0],
    };

    /// Web Mercator tiles of the default lattice.
    pub const MERCATOR: Scheme = Scheme {
        tiling: Tiling::Mercator,
        cells: LATTICE_CELLS[0],
    };

    /// Tile columns of level `z` ([`Tiling::columns`]).
    pub fn columns(self, z: u8) -> u64 {
        self.tiling.columns(z)
    }

    /// The tile rectangle `z/x/y` ([`Tiling::tile_rectangle`]).
    pub fn tile_rectangle(self, z: u8, x: u32, y: u32) -> GeoRectangle {
        self.tiling.tile_rectangle(z, x, y)
    }

    /// Lattice spacing of a level in longitude, degrees ([`Tiling::step`]).
    pub(super) fn step(self, level: u8) -> f64 {
        self.tiling.step(level, self.cells)
    }

    /// The tile column of lattice tile column `x` ([`Tiling::tile_column`]).
    pub(super) fn tile_column(self, z: u8, x: u32) -> u32 {
        self.tiling.tile_column(z, x)
    }

    /// The latitude of global lattice row `row` of `level` ([`Tiling::row_latitude`]).
    pub(super) fn row_latitude(self, level: u8, row: i64) -> f64 {
        self.tiling.row_latitude(level, self.cells, row)
    }

    /// A window of the global lattice of `level` ([`Tiling::lattice`]).
    pub(super) fn lattice(
        self,
        level: u8,
        first_column: u64,
        first_row: u64,
        width: u32,
        height: u32,
    ) -> GeoLattice {
        self.tiling
            .lattice(level, self.cells, first_column, first_row, width, height)
    }

    /// Where latitude `lat` falls among the rows of `level` ([`Tiling::row_position`]).
    pub(super) fn row_position(self, level: u8, lat: f64) -> f64 {
        self.tiling.row_position(level, self.cells, lat)
    }

    /// [`Tiling::max_row_offset`], in rows of this scheme's lattice.
    pub(super) fn max_row_offset(self, level: u8) -> usize {
        self.tiling.max_row_offset(level)
    }

    /// `u` (and `v`) per cell of a tile's lattice.
    pub(super) fn u_per_cell(self) -> u32 {
        QUANTIZED_MAX as u32 / self.cells
    }
}

/// The raster's own level for tiles of `cells` cells a side: the first whose lattice is at
/// least as fine as the raster's `resolution` (degrees).
pub(super) fn own_level(resolution: f64, tiling: Tiling, cells: u32) -> u8 {
    (0..MAX_LEVEL)
        .find(|&l| tiling.step(l, cells) <= resolution * (1.0 + 1e-9))
        .unwrap_or(MAX_LEVEL)
}

/// The cells of a pyramid's tile lattices over a raster of `resolution` degrees: of
/// [`LATTICE_CELLS`], the one whose lattice at its own level is the coarsest (the fewest
/// samples for the same detail), the first on a tie. ETOPO5 (5'): 151, 1.1 x finer than
/// its pixels each way where 217 is 1.6 x; Big Tujunga (30 m) and a 3" SRTM tile: 217.
pub fn lattice_cells(resolution: f64, tiling: Tiling) -> u32 {
    let spacing = |cells: u32| tiling.step(own_level(resolution, tiling, cells), cells);
    LATTICE_CELLS
        .into_iter()
        .reduce(|best, cells| {
            if spacing(cells) > spacing(best) {
                cells
            } else {
                best
            }
        })
        .expect("two cell counts")
}

/// WGS84 semi-major axis, metres.
pub(super) const EARTH_RADIUS: f64 = 6_378_137.0;

/// The longest triangle edge, in lattice spacings of `level`, whose chord sinks no deeper
/// than `bound` metres below the ellipsoid: CesiumJS draws each triangle flat between its
/// ECEF corners, so an edge spanning `t` radians of arc cuts `R (1 - cos(t / 2))` below the
/// surface, an error the height check (made in longitude/latitude) does not see. Measured
/// along the equator (where a lattice step spans the most arc); `None` when even the
/// tile's diagonal is short enough.
pub(super) fn max_edge_length(tiling: Tiling, cells: u32, level: u8, bound: f64) -> Option<u32> {
    let arc = 2.0 * (1.0 - (bound / EARTH_RADIUS).min(1.0)).acos();
    let spacing = tiling.step(level, cells).to_radians();
    let length = (arc / spacing).floor();
    if length >= f64::from(cells) * std::f64::consts::SQRT_2 {
        None
    } else {
        Some((length as u32).max(2))
    }
}

/// `[west, south, east, north]` in degrees, longitudes in [-180, 180]: across the
/// antimeridian `east` is wrapped back below 180, so west > east (as GeoJSON and TileJSON
/// bounding boxes have it); a raster wholly east of 180 has both wrapped.
pub(super) fn bounds_array(bounds: &GeoBounds) -> [f64; 4] {
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

/// The geographic tile rectangle `z/x/y` (TMS y) in degrees (east of 180 for `x` past the
/// last column: the same tile a turn east); [`Tiling::tile_rectangle`] for either tiling.
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
/// antimeridian the last column is past the level's last ([`Tiling::columns`]): column
/// `x` is then tile `x mod columns` (see [`Tiling::tile_column`]), at most one full turn;
/// bounds given east of 180° (longitudes in 0..360) start a turn east, on the same tiles.
/// Web Mercator rows hold only latitudes within ±85.0511°: the part of the bounds beyond
/// is not tiled.
pub(super) fn tile_range(bounds: &GeoBounds, tiling: Tiling, level: u8) -> ([u32; 2], [u32; 2]) {
    let columns = tiling.columns(level);
    let rows = 1u64 << level;
    let size = 360.0 / columns as f64;
    let clamp = |v: f64, max: u64| (v.floor().max(0.0) as u64).min(max - 1) as u32;
    // A raster whose longitudes run from 180 on (given in 0..360) starts a turn east.
    let west = clamp((bounds.west + 180.0) / size, 2 * columns);
    let x = [
        west,
        clamp((bounds.east + 180.0) / size, u64::from(west) + columns),
    ];
    let row = |lat: f64| match tiling {
        Tiling::Geographic => (lat + 90.0) / size,
        Tiling::Mercator => web_mercator_y(lat) * rows as f64,
    };
    let y = [
        clamp(row(bounds.south), rows),
        clamp(row(bounds.north), rows),
    ];
    (x, y)
}

/// A rectangle of whole tiles of one level: columns `x0 .. x0 + width` (which may run past
/// the level's last column, a turn east, see [`tile_column`]) and TMS rows `y0 .. y0 +
/// height`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct TileRect {
    pub(super) tiling: Scheme,
    pub(super) level: u8,
    pub(super) x0: u32,
    pub(super) y0: u32,
    pub(super) width: u32,
    pub(super) height: u32,
}

impl TileRect {
    /// The tiles of `level` that `bounds` touches (see [`tile_range`]).
    pub(super) fn covering(bounds: &GeoBounds, tiling: Scheme, level: u8) -> TileRect {
        let ([x0, x1], [y0, y1]) = tile_range(bounds, tiling.tiling, level);
        TileRect {
            tiling,
            level,
            x0,
            y0,
            width: x1 - x0 + 1,
            height: y1 - y0 + 1,
        }
    }

    /// Whether the rectangle goes all the way round the globe.
    pub(super) fn wraps(&self) -> bool {
        u64::from(self.width) == self.tiling.columns(self.level)
    }

    /// Tiles in the rectangle.
    pub(super) fn tiles(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Whether tile `x`, `y` (any turn) lies in the rectangle.
    pub(super) fn contains(&self, x: u32, y: u32) -> bool {
        let turn = self.tiling.columns(self.level) as i64;
        let dx = (i64::from(x) - i64::from(self.x0)).rem_euclid(turn);
        dx < i64::from(self.width) && y >= self.y0 && y - self.y0 < self.height
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest |position among level `level + 1`'s rows - index| over the rows of
    /// the lattice half as fine as `level`'s (what the coarser filter reads), over the
    /// tiles `tiles` of `level`.
    fn row_offset(level: u8, tiles: impl Iterator<Item = u64>) -> f64 {
        let cells = u64::from(LATTICE_CELLS[0]);
        let n = 1u64 << level;
        let mut worst = 0.0f64;
        for t in tiles {
            for h in 0..=2 * cells {
                let row = 2 * cells * t + h;
                let half = GeoLattice {
                    latitudes: Latitudes::WebMercatorTiles {
                        cells: 2 * LATTICE_CELLS[0],
                        tiles: n,
                    },
                    first_row: row,
                    ..Tiling::Mercator.lattice(level, LATTICE_CELLS[0], 0, 0, 1, 1)
                };
                let position =
                    Tiling::Mercator.row_position(level + 1, LATTICE_CELLS[0], half.lat(0));
                worst = worst.max((position - row as f64).abs());
            }
        }
        worst
    }

    #[test]
    fn bounds_east_of_180_cover_the_tiles_they_would_west_of_it() {
        // Fort Worth given in 0..360 (262.5 degrees) and in -180..180 (-97.5 degrees).
        let at = |west: f64| GeoBounds {
            west,
            south: 32.5,
            east: west + 0.3,
            north: 32.8,
            resolution: 0.001,
        };
        for tiling in [Tiling::Geographic, Tiling::Mercator] {
            for level in [0, 3, 10] {
                let columns = tiling.columns(level) as u32;
                let ([w0, w1], rows) = tile_range(&at(-97.5), tiling, level);
                let ([e0, e1], same_rows) = tile_range(&at(262.5), tiling, level);
                assert_eq!([e0, e1], [w0 + columns, w1 + columns], "{tiling:?} {level}");
                assert_eq!(rows, same_rows);
            }
        }
    }

    #[test]
    fn tiles_split_at_their_mercator_middle_by_a_bounded_offset() {
        // Run with --nocapture for the table of offsets (rows of the finer level).
        for level in 0..=12u8 {
            let n = 1u64 << level;
            // Every tile up to level 6, then the northern 64 (the worst) and the equator.
            let tiles: Vec<u64> = if n <= 64 {
                (0..n).collect()
            } else {
                (n - 64..n).chain(n / 2 - 2..n / 2 + 2).collect()
            };
            let offset = row_offset(level, tiles.into_iter());
            println!("level {level}: {offset:.2} rows");
            assert!(
                offset <= Tiling::Mercator.max_row_offset(level) as f64,
                "{level}"
            );
            if level == 1 {
                // Rows taken as every other finer row would sit 100+ rows off.
                assert!(offset > 100.0);
            }
        }
        assert_eq!(Tiling::Geographic.max_row_offset(3), 0);
    }

    #[test]
    fn the_lattice_is_the_least_finer_than_the_raster() {
        let geographic = |resolution: f64| lattice_cells(resolution, Tiling::Geographic);
        // ETOPO5 (5'): level 4 either way, 0.075° with 151 cells against 0.052° with 217.
        assert_eq!(geographic(5.0 / 60.0), 151);
        assert_eq!(own_level(5.0 / 60.0, Tiling::Geographic, 151), 4);
        // Big Tujunga (30 m, 0.00027°): level 12's 0.00020° with 217; 151 needs level 13.
        assert_eq!(geographic(0.00027), 217);
        // A 3" SRTM tile: level 10's 0.00081° with 217 is within 3 % of its pixels.
        assert_eq!(geographic(3.0 / 3600.0), 217);
        // Either way, the lattice at the raster's own level is at least as fine as the
        // raster and less than twice as fine.
        for k in 0..200 {
            let resolution = 1e-5 * 1.07f64.powi(k);
            for tiling in [Tiling::Geographic, Tiling::Mercator] {
                let cells = lattice_cells(resolution, tiling);
                let level = own_level(resolution, tiling, cells);
                let step = tiling.step(level, cells);
                assert!(step <= resolution * (1.0 + 1e-9) || level == MAX_LEVEL);
                assert!(step > resolution / 2.0 || level == 0);
                for other in LATTICE_CELLS {
                    let other_step = tiling.step(own_level(resolution, tiling, other), other);
                    assert!(
                        step >= other_step,
                        "{resolution}: {cells} {step} {other_step}"
                    );
                }
            }
        }
    }

    #[test]
    fn mercator_rectangles_meet_and_end_at_85_degrees() {
        let top = Tiling::Mercator.tile_rectangle(3, 5, 7);
        assert!((top.north - 85.051_128_779_806_59).abs() < 1e-12);
        assert_eq!(Tiling::Mercator.tile_rectangle(1, 0, 0).north, 0.0);
        let (a, b) = (
            Tiling::Mercator.tile_rectangle(9, 3, 300),
            Tiling::Mercator.tile_rectangle(9, 3, 301),
        );
        assert_eq!(a.north, b.south);
        // The lattice's edge rows are the rectangles' edges, to the bit.
        for cells in LATTICE_CELLS {
            let row = |r: i64| Tiling::Mercator.row_latitude(9, cells, r);
            assert_eq!(row(301 * i64::from(cells)), b.south);
            assert_eq!(row(302 * i64::from(cells)), b.north);
        }
    }
}
