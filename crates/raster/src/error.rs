//! The error type of raster reading: every variant names the file it is about.

use std::path::{Path, PathBuf};

/// What can go wrong while reading a raster or transforming coordinates; every message
/// about a raster starts with the file's path.
///
/// The variants are split by what the caller does next: fix the path ([`Error::NotFound`]),
/// pick another file ([`Error::NotARaster`], [`Error::UnsupportedType`], [`Error::Read`]),
/// pick another band ([`Error::BandOutOfRange`], [`Error::AllNodata`]) or tile the input
/// ([`Error::TooLarge`]). [`Error::Crs`] and [`Error::Untransformable`] come from
/// reprojection, which has no file of its own: the caller names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Nothing exists at the path.
    #[error("{}: no such file", path.display())]
    NotFound {
        /// The path that was asked for.
        path: PathBuf,
    },
    /// The path exists, but no GDAL raster driver can open it (a directory, an empty or text
    /// file, a vector-only format, a corrupt header, an unreadable file, ...).
    #[error("{}: not a raster GDAL can read ({reason})", path.display())]
    NotARaster {
        /// The file.
        path: PathBuf,
        /// GDAL's explanation, without GDAL's framing.
        reason: String,
        /// The error GDAL returned (boxed: it is large).
        #[source]
        source: Box<gdal::errors::GdalError>,
    },
    /// The path is a pipe, socket or character device (`/dev/zero`), not a regular file:
    /// GDAL would block on a FIFO with no writer, and reads rasters by seeking.
    #[error(
        "{}: is a pipe, socket or device, not a file: GDAL reads rasters from files it \
         can seek (save the stream to a file first)",
        path.display()
    )]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// The file's name is not valid UTF-8, and GDAL is given file names as UTF-8 text.
    #[error(
        "{}: the file name is not valid UTF-8, which cannot be passed to GDAL; rename the file \
         (or link to it under a UTF-8 name)",
        path.display()
    )]
    NameNotUtf8 {
        /// The path.
        path: PathBuf,
    },
    /// The file has no band of its own, only subdatasets (a netCDF or HDF5 container).
    #[error(
        "{}: has no raster band of its own but {count} subdataset(s), such as {first}; give \
         one of them as the input (`gdalinfo` lists them)",
        path.display()
    )]
    Subdatasets {
        /// The file.
        path: PathBuf,
        /// How many subdatasets it lists.
        count: usize,
        /// The first one's name, as GDAL opens it.
        first: String,
    },
    /// The requested band does not exist (bands are numbered from 1).
    #[error("{}: band {band} out of range, the raster has {count} band(s)", path.display())]
    BandOutOfRange {
        /// The file.
        path: PathBuf,
        /// The 1-based band that was asked for.
        band: usize,
        /// How many bands the raster has.
        count: usize,
    },
    /// The band holds complex or otherwise non-real samples.
    #[error(
        "{}: band {band} has data type {data_type}, which is not a real-valued sample type \
         (complex types such as CInt16 or CFloat32 show as Unknown); convert it first, for \
         example with gdal_translate -ot Float32",
        path.display()
    )]
    UnsupportedType {
        /// The file.
        path: PathBuf,
        /// The 1-based band.
        band: usize,
        /// GDAL's name of the band's data type.
        data_type: String,
    },
    /// The raster has more samples than one [`tinsmith_georef::Samples`] can hold.
    #[error(
        "{}: {width}x{height} samples is too large for one grid (at most 2^32-2 samples)",
        path.display()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
    /// GDAL failed while reading sample values (a truncated or corrupt file, an I/O error).
    #[error("{}: reading band {band} failed ({reason})", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The 1-based band.
        band: usize,
        /// GDAL's explanation, without GDAL's framing.
        reason: String,
        /// The error GDAL returned (boxed: it is large).
        #[source]
        source: Box<gdal::errors::GdalError>,
    },
    /// Every sample of the band is nodata (equal to the band's nodata value, NaN or infinite).
    #[error("{}: band {band} has no valid sample (all nodata)", path.display())]
    AllNodata {
        /// The file.
        path: PathBuf,
        /// The 1-based band.
        band: usize,
    },
    /// Reprojection ([`crate::to_wgs84`], [`crate::from_wgs84`]): GDAL cannot read a CRS, or PROJ cannot transform between
    /// two. Not about a file: the caller names the file the coordinates belong to.
    #[error("{reason}")]
    Crs {
        /// What failed.
        reason: String,
        /// The error GDAL returned (boxed: it is large).
        #[source]
        source: Box<gdal::errors::GdalError>,
    },
    /// A window asked of [`crate::WindowReader::read_window`] is empty or reaches past the
    /// raster's edge.
    #[error(
        "{}: window of {width}x{height} samples at ({x0}, {y0}) is not inside the \
         {raster_width}x{raster_height} raster",
        path.display()
    )]
    WindowOutOfRange {
        /// The file.
        path: PathBuf,
        /// First column of the window.
        x0: u32,
        /// First row of the window.
        y0: u32,
        /// Columns asked for.
        width: u32,
        /// Rows asked for.
        height: u32,
        /// Columns of the raster.
        raster_width: u32,
        /// Rows of the raster.
        raster_height: u32,
    },
    /// The raster has no CRS or no geotransform, so it cannot be placed on the globe.
    #[error("{}: {missing}, so it cannot be placed on the globe (EPSG:4326); {hint}", path.display())]
    NotGeoreferenced {
        /// The file.
        path: PathBuf,
        /// What is missing: "no CRS", "no geotransform" or both.
        missing: &'static str,
        /// How to give it.
        hint: &'static str,
    },
    /// Heights cannot be turned into heights above the WGS84 ellipsoid: the raster's
    /// vertical CRS is not one tinsmith knows, or PROJ cannot use the geoid grid.
    #[error("{}: {reason}", path.display())]
    VerticalDatum {
        /// The raster, or the geoid grid.
        path: PathBuf,
        /// What is wrong and what to do.
        reason: String,
    },
    /// A polygon layer could not be read or burnt onto a grid.
    #[error("{}: cannot burn its polygons onto a grid ({reason})", path.display())]
    Polygons {
        /// The vector file.
        path: PathBuf,
        /// GDAL's or PROJ's explanation.
        reason: String,
    },
    /// A line or polygon layer (breaklines, an outline) could not be read as lines.
    #[error("{}: {reason}", path.display())]
    Lines {
        /// The vector file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// GDAL failed to reproject the raster to EPSG:4326.
    #[error("{}: reprojecting to EPSG:4326 failed ({reason})", path.display())]
    Warp {
        /// The file.
        path: PathBuf,
        /// GDAL's explanation.
        reason: String,
        /// The error GDAL returned (boxed: it is large).
        #[source]
        source: Box<gdal::errors::GdalError>,
    },
    /// A raster could not be resampled onto another raster's grid.
    #[error("{}: cannot be resampled onto the grid of {} ({reason})", path.display(), target.display())]
    Resample {
        /// The raster to resample.
        path: PathBuf,
        /// The raster whose grid it was to be put on.
        target: PathBuf,
        /// Why (GDAL's explanation, or what the grids lack).
        reason: String,
    },
    /// Reprojection: PROJ maps a point to no finite position (outside the area
    /// the projection is defined on).
    #[error("point {point} at {position:?} cannot be transformed")]
    Untransformable {
        /// Position of the point in the slice.
        point: usize,
        /// Its coordinates before the transformation.
        position: [f64; 3],
    },
    /// The samples read cannot form a grid (a dimension of zero, or too many samples).
    #[error("{}: band {band} cannot become a grid", path.display())]
    Grid {
        /// The file.
        path: PathBuf,
        /// The 1-based band.
        band: usize,
        /// Why ([`tinsmith_georef::Samples::new`]'s reason, worded as the core words it).
        #[source]
        source: tinsmith_georef::SamplesError,
    },
}

/// Result of this crate's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;

/// GDAL's own message inside a [`gdal::errors::GdalError`], without the crate's framing
/// ("GDAL method 'X' returned a NULL pointer. Error msg: ...") and without the mentions of
/// `path` that the error message already starts with (`` `path' ``, `path, band 1: `,
/// `path: `); falls back to the whole display text when there is no message.
pub(crate) fn gdal_reason(err: &gdal::errors::GdalError, path: &Path) -> String {
    use gdal::errors::GdalError;
    let msg = match err {
        GdalError::NullPointer { msg, .. } | GdalError::CplError { msg, .. } => msg.trim(),
        _ => "",
    };
    if msg.is_empty() {
        return err.to_string();
    }
    let p = path.to_string_lossy();
    let mut reason = msg
        .replace(&format!("`{p}' "), "")
        .replace(&format!("{p}: "), "");
    while let Some(start) = reason.find(&format!("{p}, band ")) {
        // "path, band 1: " -> ""
        match reason[start..].find(": ") {
            Some(colon) => reason.replace_range(start..start + colon + 2, ""),
            None => break,
        }
    }
    let reason = reason.trim().trim_end_matches('.').trim();
    if reason.is_empty() {
        msg.to_string()
    } else {
        reason.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gdal::errors::GdalError;

    #[test]
    fn reason_strips_gdal_framing_and_the_path() {
        let path = Path::new("/d/x.txt");
        let err = GdalError::NullPointer {
            method_name: "GDALOpenEx",
            msg: "`/d/x.txt' not recognized as a supported file format.\n".into(),
        };
        assert_eq!(
            gdal_reason(&err, path),
            "not recognized as a supported file format"
        );
        let path = Path::new("/d/t.asc");
        let err = GdalError::CplError {
            class: 3,
            number: 1,
            msg: "/d/t.asc, band 1: IReadBlock failed at X offset 0, Y offset 27: /d/t.asc, \
                  band 1: File short, can't read line 27."
                .into(),
        };
        assert_eq!(
            gdal_reason(&err, path),
            "IReadBlock failed at X offset 0, Y offset 27: File short, can't read line 27"
        );
        let err = GdalError::CplError {
            class: 4,
            number: 4,
            msg: "/d/s.tif: No such file".into(),
        };
        assert_eq!(
            gdal_reason(&err, path),
            "/d/s.tif: No such file",
            "other paths stay"
        );
    }

    #[test]
    fn reason_falls_back_to_display_without_message() {
        let err = GdalError::NullPointer {
            method_name: "GDALOpenEx",
            msg: String::new(),
        };
        assert!(gdal_reason(&err, Path::new("a")).contains("GDALOpenEx"));
    }

    #[test]
    fn messages_start_with_the_path() {
        let err = Error::BandOutOfRange {
            path: "a/b.tif".into(),
            band: 3,
            count: 1,
        };
        assert_eq!(
            err.to_string(),
            "a/b.tif: band 3 out of range, the raster has 1 band(s)"
        );
        let err = Error::AllNodata {
            path: "c.asc".into(),
            band: 1,
        };
        assert_eq!(
            err.to_string(),
            "c.asc: band 1 has no valid sample (all nodata)"
        );
        let err = Error::NotFound {
            path: "nope.tif".into(),
        };
        assert_eq!(err.to_string(), "nope.tif: no such file");
    }
}
