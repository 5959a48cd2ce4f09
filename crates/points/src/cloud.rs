//! Points as compact lattice arrays: integer positions on a regular lattice with an
//! origin and a spacing per axis, and `f64` heights.

/// Where the CRS of a point file came from.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct FileCrs {
    /// The WKT of a LAS OGC WKT (E)VLR.
    pub wkt: Option<String>,
    /// The EPSG code of a LAS GeoTIFF key directory (projected, else geographic key).
    pub geotiff_epsg: Option<u16>,
}

/// Which LAS classes were kept.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClassChoice {
    /// Every class (text input, or a LAS file without ground points and no `classes`).
    All,
    /// Only ground (class 2): the default when the file has any ground point.
    DefaultGround,
    /// The classes asked for.
    Listed(Vec<u8>),
}

/// Points read from a file: lattice positions (x right, y up) and heights, in file order
/// until [`crate::dedupe`] sorts them.
///
/// World position of point `i`: `origin + spacing * xy[i]` per axis. Lattice coordinates
/// are in `0..=MAX_LATTICE` on both axes.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud {
    /// Lattice positions.
    pub xy: Vec<[i64; 2]>,
    /// Heights, finite.
    pub z: Vec<f64>,
    /// World coordinates of lattice position (0, 0).
    pub origin: [f64; 2],
    /// World distance between lattice positions along x and y.
    pub spacing: [f64; 2],
    /// The CRS the file declares, if any.
    pub crs: FileCrs,
    /// Which classes were kept (LAS).
    pub classes: ClassChoice,
    /// Points in the file, before any filter.
    pub points_in_file: u64,
}

/// The largest lattice coordinate: differences below 2^31 keep the decimator's
/// orientation determinants exact in `i64` (`tinsmith_core::MAX_SCATTER_COORDINATE`).
pub const MAX_LATTICE: i64 = (1 << 31) - 1;

impl PointCloud {
    /// World x, y of point `i`.
    pub fn world(&self, i: usize) -> [f64; 2] {
        let [x, y] = self.xy[i];
        [
            self.origin[0] + self.spacing[0] * x as f64,
            self.origin[1] + self.spacing[1] * y as f64,
        ]
    }
}
