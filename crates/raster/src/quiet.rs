//! Keeping GDAL's own error and warning printing off standard error.

use std::sync::Mutex;

use gdal::errors::CplErrType;

/// GDAL's warnings since [`silence_gdal_errors`], distinct, in order, until
/// [`take_gdal_warnings`] takes them.
static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// How many distinct warnings are held; later ones are dropped (a warning repeated for
/// every tile is held once).
const MAX_HELD_WARNINGS: usize = 20;

/// Stops GDAL from printing its errors (`ERROR 4: ... not recognized as a supported file
/// format`) and warnings to standard error, for the whole process. Warnings are held for
/// [`take_gdal_warnings`]; debug messages (`CPL_DEBUG`) are still printed, prefixed with
/// `GDAL debug:`.
///
/// Nothing is lost: the functions of this crate return GDAL's error message inside their
/// [`crate::Error`], so a failed run says why in one line, which the warnings GDAL gives
/// on the way (a malformed TIFF's tags) would only bury. Call this once, early, from a
/// binary (a library should leave GDAL's process-wide handler alone); calling it again is
/// harmless. It replaces any error handler installed before through
/// `gdal::config::set_error_handler`.
pub fn silence_gdal_errors() {
    // Called from C: a closed stderr or a poisoned lock must not panic here (that would
    // abort the process).
    gdal::config::set_error_handler(|class, _number, msg| match class {
        // Int64/UInt64 nodata is read with the exact getters; GDAL's own readers (the
        // warper's) still take the f64 one, which says so.
        CplErrType::Warning if msg.contains("returns an approximate value") => {}
        CplErrType::Warning => {
            if let Ok(mut held) = WARNINGS.lock() {
                if held.len() < MAX_HELD_WARNINGS && !held.iter().any(|w| w == msg) {
                    held.push(msg.to_owned());
                }
            }
        }
        CplErrType::Debug => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "GDAL debug: {msg}");
        }
        CplErrType::None | CplErrType::Failure | CplErrType::Fatal => {}
    });
}

/// The warnings GDAL gave since [`silence_gdal_errors`] (or the last call), distinct and
/// in order, at most 20: for a binary to print once a run has succeeded. A failed run's
/// error names the file and the problem alone.
pub fn take_gdal_warnings() -> Vec<String> {
    match WARNINGS.lock() {
        Ok(mut held) => std::mem::take(&mut *held),
        Err(poisoned) => std::mem::take(&mut *poisoned.into_inner()),
    }
}

/// Set once a dataset read through HDF5 (GDAL's netCDF or HDF5 drivers) has been opened:
/// from then on [`silence_hdf5_on_this_thread`] acts. Rasters of other formats never load
/// or start HDF5 for it.
static HDF5_INPUT: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Notes that a dataset opened by GDAL's `driver` (short name) reads through HDF5.
pub(crate) fn note_driver(driver: &str) {
    if driver == "netCDF" || driver.starts_with("HDF5") {
        HDF5_INPUT.store(true, std::sync::atomic::Ordering::Relaxed);
    }
}

/// Stops HDF5 (under GDAL's netCDF and HDF5 drivers) from printing its error stacks
/// (`HDF5-DIAG: Error detected in HDF5 ...`) on the calling thread, once an HDF5-based
/// dataset has been opened (see [`note_driver`]; the first open is on the main thread,
/// before any worker's).
///
/// The netCDF library turns HDF5's printing off in the thread that first opens a file, but
/// a thread-safe HDF5 keeps that setting per thread, so tile workers opening the same
/// netCDF-4 file printed a page of stacks for attributes the driver merely probes. Nothing
/// is lost: failures that matter come back through GDAL. A HDF5 built without thread
/// safety keeps one setting for the process, which netCDF has already made, and is left
/// alone (calling it from a worker could race with another thread inside HDF5). Looked up
/// at run time (`dlsym`), so a GDAL without HDF5 needs nothing; cheap after the first call
/// on each thread.
#[allow(unsafe_code)]
pub(crate) fn silence_hdf5_on_this_thread() {
    use std::cell::Cell;
    use std::sync::atomic::Ordering;
    /// `herr_t H5Eset_auto2(hid_t estack_id, H5E_auto2_t func, void *client_data)`.
    type SetAuto = unsafe extern "C" fn(i64, *const libc::c_void, *mut libc::c_void) -> i32;
    /// `herr_t H5is_library_threadsafe(hbool_t *is_ts)` (`hbool_t` is a C `bool`).
    type IsThreadsafe = unsafe extern "C" fn(*mut bool) -> i32;
    thread_local!(static DONE: Cell<bool> = const { Cell::new(false) });
    if !HDF5_INPUT.load(Ordering::Relaxed) || DONE.with(Cell::get) {
        return;
    }
    // SAFETY: dlsym with NUL-terminated names; a non-null result is HDF5's exported
    // function of that name, whose C signature is the type it is cast to (hid_t is 64-bit
    // since HDF5 1.10; on x86-64 and aarch64 a 0 passed as i64 is also a 0 int for 1.8).
    let lookup = |name: &std::ffi::CStr| unsafe { libc::dlsym(libc::RTLD_DEFAULT, name.as_ptr()) };
    let (set_auto, is_threadsafe) = (lookup(c"H5Eset_auto2"), lookup(c"H5is_library_threadsafe"));
    if set_auto.is_null() || is_threadsafe.is_null() {
        // Not loaded (yet, if GDAL's driver is a plugin): try again at the next open.
        return;
    }
    DONE.with(|done| done.set(true));
    let (set_auto, is_threadsafe) = unsafe {
        (
            std::mem::transmute::<*mut libc::c_void, SetAuto>(set_auto),
            std::mem::transmute::<*mut libc::c_void, IsThreadsafe>(is_threadsafe),
        )
    };
    let mut threadsafe = false;
    // SAFETY: H5is_library_threadsafe writes the flag it is given and nothing else;
    // H5Eset_auto2(H5E_DEFAULT = 0, NULL, NULL) is the documented way to turn HDF5's
    // automatic error printing off, and only runs on a thread-safe HDF5.
    unsafe {
        if is_threadsafe(&mut threadsafe) >= 0 && threadsafe {
            set_auto(0, std::ptr::null(), std::ptr::null_mut());
        }
    }
}
