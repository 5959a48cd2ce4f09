//! Reads one band of any raster GDAL can open into [`tinsmith_georef::Samples`] of
//! heights: plain data, from which the decimation core builds its grid.
//!
//! [`read_samples`] returns the samples (nodata as NaN) with a [`RasterInfo`]: driver, size, data
//! type, nodata value, CRS (WKT and EPSG code), geotransform and statistics of the samples.
//! [`to_wgs84`] and [`from_wgs84`] transform coordinates between a CRS and WGS84
//! longitude, latitude (for RFC 7946 GeoJSON), so that no other crate links GDAL.
//! [`open_info`] gives the same [`RasterInfo`] without keeping the samples. For rasters
//! too large for one grid, [`WindowReader`] (or [`read_window`]) reads a rectangle at a
//! time, decoded exactly as [`read_samples`] decodes the whole band, and
//! [`RasterInfo::max_abs_value`] of [`open_info`] gives the raster-wide largest |height|.
//! For terrain tiles, [`geographic_bounds`] places a raster in EPSG:4326 and
//! [`sample_geographic`] samples it on a longitude/latitude lattice, each sample a function
//! of the raster and its position alone.
//!
//! # What callers can rely on
//! - **Nodata.** A sample is nodata exactly when it is NaN or infinite, is zero in the
//!   band's mask (a GDAL mask band, or an alpha band of any type), or equals the band's
//!   nodata value compared in the band's own type: Float32 bands compare in single precision
//!   (a `-3.4e38` declared in text matches the `f32` stored in the pixels) and floats within
//!   GDAL's own tolerance, as `gdalinfo -stats` counts them; integer bands match a nodata
//!   value only when it is an integer the type can hold (any other matches nothing).
//!   Nodata samples are NaN in the samples; all other samples are finite.
//! - **Heights.** Valid samples are mapped through the band's scale and offset when it has
//!   them, so every height is in the band's real unit.
//! - **Geotransform.** `None` when the dataset has none (GDAL reports an identity default
//!   with an error for such files; that default is never returned as a geotransform).
//! - **Errors.** Every [`Error`] message starts with the path and names the problem: a
//!   missing file, a file no GDAL raster driver can read, a band out of range, a
//!   non-real-valued band, a raster too large for one grid, a failed read, or a band with
//!   no valid sample ([`read_samples`] only). GDAL's explanation, when it gave one, is part of
//!   the message (without its repetition of the path), and GDAL's error is kept as the
//!   [`std::error::Error::source`].
//! - **Threads.** Each call opens its own GDAL dataset and closes it before returning, so
//!   the functions can be called from several threads at once. A [`WindowReader`] keeps
//!   its dataset open: it can move between threads but not be shared; open one per thread.
//!
//! GDAL also prints its errors and warnings to standard error by default;
//! [`silence_gdal_errors`] stops that for the whole process (the errors' messages stay in
//! the returned errors; the warnings are held for [`take_gdal_warnings`]).
//!
//! # Example
//! ```no_run
//! use std::path::Path;
//!
//! # fn main() -> Result<(), tinsmith_raster::Error> {
//! let raster = tinsmith_raster::read_samples(Path::new("tests/fixtures/landlab_hugo_site.asc"), 1)?;
//! let info = &raster.info;
//! println!(
//!     "{}: {}x{} {} ({} valid samples, heights {:?}..{:?})",
//!     info.driver, info.width, info.height, info.data_type, info.valid_samples, info.min, info.max
//! );
//! assert_eq!(raster.samples.valid_count() as u64, info.valid_samples);
//! # Ok(())
//! # }
//! ```

mod bilinear;
mod cache;
mod coverage;
mod datum;
mod decode;
mod error;
mod files;
mod geographic;
mod info;
mod lines;
mod point_layer;
mod polygons;
mod projected;
mod quiet;
mod read;
mod reproject;
mod resample;
mod sample;
mod window;

pub use cache::limit_block_cache;
pub use coverage::{coverage, Coverage};
pub use datum::{declared_vertical_datum, Geoid, VerticalDatum};
pub use error::{Error, Result};
pub use files::input_files;
pub use geographic::{
    geographic_bounds, heights_may_exceed_f32, web_mercator_latitude, web_mercator_y, GeoBounds,
    GeoLattice, Latitudes,
};
pub use info::{Raster, RasterInfo};
pub use lines::{read_lines, LineLayer};
pub use point_layer::{is_point_layer, read_point_layer, PointLayer};
pub use polygons::{burn_polygons, is_vector};
pub use quiet::{silence_gdal_errors, take_gdal_warnings};
pub use read::{open_info, open_info_on, open_info_with_progress, read_samples, read_samples_on};
pub use reproject::{
    crs_wkt, epsg_code, from_wgs84, horizontal_crs, is_geographic, is_wgs84_lon_lat, same_crs,
    to_wgs84,
};
pub use resample::{on_same_grid, resample_onto, Resampling};
pub use sample::sample_geographic;
pub use window::{read_window, WindowReader};
