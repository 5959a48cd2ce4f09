//! The TMS geographic tiling (EPSG:4326, two level-0 tiles) and each tile's lattice of
//! `TILE_CELLS` cells a side.

use crate::quantized_mesh::{GeoRectangle, QUANTIZED_MAX};
use tinsmith_raster::GeoBounds;

/// Cells along each side of a tile's sample grid: each tile samples
/// `(TILE_CELLS + 1)^2` lattice points. 217 divides 32767 (= 7 x 31 x 151), so sample `i`
/// is at `u = 151 i` exactly: decoded vertices sit exactly on their source samples.
pub const TILE_CELLS: u32 = 217;

/// `u` (and `v`) per cell of the tile grid.
pub(super) const U_PER_CELL: u32 = QUANTIZED_MAX as u32 / TILE_CELLS;

/// Lattice spacing of a level, in degrees.
pub(super) fn step(level: u8) -> f64 {
    180.0 / (f64::from(TILE_CELLS) * (1u64 << level) as f64)
}

/// WGS84 semi-major axis, metres.
pub(super) const EARTH_RADIUS: f64 = 6_378_137.0;

/// The longest triangle edge, in lattice spacings of `level`, whose chord sinks no deeper
/// than `bound` metres below the ellipsoid: CesiumJS draws each triangle flat between its
/// ECEF corners, so an edge spanning `t` radians of arc cuts `R (1 - cos(t / 2))` below the
/// surface, an error the height check (made in longitude/latitude) does not see. Measured
/// along the equator (where a lattice step spans the most arc); `None` when even the
/// tile's diagonal is short enough.
pub(super) fn max_edge_length(level: u8, bound: f64) -> Option<u32> {
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

/// The tile column of lattice tile column `x` (which is past the last column across the
/// antimeridian, see [`tile_range`]).
pub(super) fn tile_column(z: u8, x: u32) -> u32 {
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
pub(super) fn tile_range(bounds: &GeoBounds, level: u8) -> ([u32; 2], [u32; 2]) {
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

/// A rectangle of whole tiles of one level: columns `x0 .. x0 + width` (which may run past
/// the level's last column, a turn east, see [`tile_column`]) and TMS rows `y0 .. y0 +
/// height`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct TileRect {
    pub(super) level: u8,
    pub(super) x0: u32,
    pub(super) y0: u32,
    pub(super) width: u32,
    pub(super) height: u32,
}

impl TileRect {
    /// The tiles of `level` that `bounds` touches (see [`tile_range`]).
    pub(super) fn covering(bounds: &GeoBounds, level: u8) -> TileRect {
        let ([x0, x1], [y0, y1]) = tile_range(bounds, level);
        TileRect {
            level,
            x0,
            y0,
            width: x1 - x0 + 1,
            height: y1 - y0 + 1,
        }
    }

    /// Whether the rectangle goes all the way round the globe.
    pub(super) fn wraps(&self) -> bool {
        u64::from(self.width) == 2u64 << self.level
    }

    /// Tiles in the rectangle.
    pub(super) fn tiles(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Whether tile `x`, `y` (any turn) lies in the rectangle.
    pub(super) fn contains(&self, x: u32, y: u32) -> bool {
        let turn = 2i64 << self.level;
        let dx = (i64::from(x) - i64::from(self.x0)).rem_euclid(turn);
        dx < i64::from(self.width) && y >= self.y0 && y - self.y0 < self.height
    }
}
