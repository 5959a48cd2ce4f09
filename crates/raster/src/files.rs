//! The files a raster is made of, so that no output overwrites one of them.

use std::ffi::CStr;
use std::path::{Path, PathBuf};

/// Every file GDAL reads for the raster at `path`, canonicalized: the file itself and
/// whatever else it names or finds beside it (a VRT's sources, an ENVI `.hdr`, a world
/// file, a `.prj`, the `.aux.xml` that holds a PNG's georeferencing). Writing over any of
/// them would change or destroy the input. Empty when GDAL cannot open `path`; files that
/// do not exist are left out.
pub fn input_files(path: &Path) -> Vec<PathBuf> {
    let Ok(dataset) = crate::read::open_dataset(path) else {
        return Vec::new();
    };
    let mut names = Vec::new();
    // SAFETY: GDALGetFileList returns a NULL-terminated array of NUL-terminated strings
    // (or NULL) owned by the caller, freed once with CSLDestroy after it is copied; the
    // dataset outlives the call.
    #[allow(unsafe_code)]
    unsafe {
        let list = gdal_sys::GDALGetFileList(dataset.c_dataset());
        if !list.is_null() {
            let mut i = 0;
            while !(*list.add(i)).is_null() {
                names.push(CStr::from_ptr(*list.add(i)).to_string_lossy().into_owned());
                i += 1;
            }
            gdal_sys::CSLDestroy(list);
        }
    }
    let mut files: Vec<PathBuf> = names
        .iter()
        .filter_map(|name| std::fs::canonicalize(name).ok())
        .collect();
    if let Ok(own) = std::fs::canonicalize(path) {
        files.push(own);
    }
    files.sort();
    files.dedup();
    files
}
