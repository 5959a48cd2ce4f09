//! Plain raster samples and where they go: the data that ingestion hands to the
//! decimator and the map from grid positions to the coordinates written in mesh files.
//!
//! This crate depends on no other tinsmith crate and links no GDAL, so a reader, the
//! decimation core, the tiled engine and the pipeline can all share these types
//! without depending on one another.
//!
//! - [`Samples`]: a `width` x `height` block of heights in row-major order, NaN marking
//!   nodata, as a raster reader returns it (no decimation caches are built).
//! - [`GeoTransform`]: GDAL's six-coefficient affine map from pixel corners to world
//!   coordinates, with its inverse at sample centres.
//! - [`Placement`]: how grid positions become file coordinates (pixel coordinates, or the
//!   world position of each sample's centre) and back ([`Placement::sample_at`], within
//!   the tolerance of a file format's rounding: [`F64_SAMPLE_TOLERANCE`],
//!   [`F32_SAMPLE_TOLERANCE`], [`WGS84_SAMPLE_TOLERANCE`]).
//!
//! # Example
//! ```
//! use tinsmith_georef::{GeoTransform, Placement, Samples, F64_SAMPLE_TOLERANCE};
//!
//! let samples = Samples::new(2, 2, vec![1.0, 2.0, f64::NAN, 4.0]).unwrap();
//! assert_eq!(samples.valid_count(), 3);
//! assert_eq!(samples.get(0, 1), None);
//!
//! let north_up = GeoTransform([500.0, 30.0, 0.0, 4000.0, 0.0, -30.0]);
//! let placement = Placement::new(Some(north_up), false);
//! let p = placement.file_position(1, 1);
//! assert_eq!(p, [545.0, 3955.0]);
//! assert_eq!(placement.sample_at(p, F64_SAMPLE_TOLERANCE).unwrap(), [1, 1]);
//! assert!(placement.flips_orientation());
//! ```

mod geo_transform;
mod number;
mod placement;
mod samples;

pub use geo_transform::GeoTransform;
pub use number::readable;
pub use placement::{
    Placement, PlacementProblem, PositionError, F32_SAMPLE_TOLERANCE, F64_SAMPLE_TOLERANCE,
    WGS84_SAMPLE_TOLERANCE,
};
pub use samples::{Samples, SamplesError};
