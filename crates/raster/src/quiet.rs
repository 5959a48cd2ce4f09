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
    // Called from C: a closed stderr must not panic here (that would abort the process).
    gdal::config::set_error_handler(|class, _number, msg| {
        use std::io::Write as _;
        let prefix = match class {
            // Int64/UInt64 nodata is read with the exact getters; GDAL's own readers (the
            // warper's) still take the f64 one, which says so.
            CplErrType::Warning if msg.contains("returns an approximate value") => return,
            CplErrType::Warning => "GDAL warning",
            CplErrType::Debug => "GDAL debug",
            CplErrType::None | CplErrType::Failure | CplErrType::Fatal => return,
        };
        let _ = writeln!(std::io::stderr(), "{prefix}: {msg}");
    });
}
