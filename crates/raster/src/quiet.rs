//! Keeping GDAL's own error printing off standard error.

use gdal::errors::CplErrType;

/// Stops GDAL from printing its errors (`ERROR 4: ... not recognized as a supported file
/// format`) to standard error, for the whole process. Warnings and debug messages are still
/// printed, prefixed with `GDAL warning:` or `GDAL debug:`.
///
/// Nothing is lost: the functions of this crate return GDAL's error message inside their
/// [`crate::Error`]. Call this once, early, from a binary (a library should leave GDAL's
/// process-wide handler alone); calling it again is harmless. It replaces any error handler
/// installed before through `gdal::config::set_error_handler`.
pub fn silence_gdal_errors() {
    gdal::config::set_error_handler(|class, _number, msg| match class {
        CplErrType::Warning => eprintln!("GDAL warning: {msg}"),
        CplErrType::Debug => eprintln!("GDAL debug: {msg}"),
        CplErrType::None | CplErrType::Failure | CplErrType::Fatal => {}
    });
}
