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

/// Stops HDF5 (under GDAL's netCDF and HDF5 drivers) from printing its error stacks
/// (`HDF5-DIAG: Error detected in HDF5 ...`) on the calling thread.
///
/// The netCDF library turns HDF5's printing off in the thread that first opens a file, but
/// HDF5 keeps that setting per thread, so tile workers opening the same netCDF-4 file printed
/// a page of stacks for attributes the driver merely probes. Nothing is lost: failures that
/// matter come back through GDAL. Looked up at run time (`dlsym`), so a GDAL built without
/// HDF5 needs nothing; cheap after the first call on each thread.
#[allow(unsafe_code)]
pub(crate) fn silence_hdf5_on_this_thread() {
    use std::cell::Cell;
    use std::sync::OnceLock;
    /// `herr_t H5Eset_auto2(hid_t estack_id, H5E_auto2_t func, void *client_data)`.
    type SetAuto = unsafe extern "C" fn(i64, *const libc::c_void, *mut libc::c_void) -> i32;
    static SET_AUTO: OnceLock<Option<SetAuto>> = OnceLock::new();
    thread_local!(static DONE: Cell<bool> = const { Cell::new(false) });
    if DONE.with(|done| done.replace(true)) {
        return;
    }
    let set_auto = SET_AUTO.get_or_init(|| {
        // SAFETY: dlsym with a NUL-terminated name; a non-null result is HDF5's exported
        // H5Eset_auto2, whose C signature is `SetAuto` (hid_t is 64-bit since HDF5 1.10; on
        // x86-64 and aarch64 a 0 passed as i64 is also a 0 int for 1.8).
        let symbol = unsafe { libc::dlsym(libc::RTLD_DEFAULT, c"H5Eset_auto2".as_ptr()) };
        (!symbol.is_null())
            .then(|| unsafe { std::mem::transmute::<*mut libc::c_void, SetAuto>(symbol) })
    });
    if let Some(set_auto) = set_auto {
        // H5E_DEFAULT is 0; a null function turns the automatic printing off.
        // SAFETY: the documented way to disable HDF5's automatic error printing.
        unsafe { set_auto(0, std::ptr::null(), std::ptr::null_mut()) };
    }
}
