//! The files a raster is made of, so that no output overwrites one of them.

use std::ffi::CStr;
use std::path::{Path, PathBuf};

/// Every file GDAL reads for the raster at `path`, canonicalized: the file itself and
/// whatever else it names or finds beside it (a VRT's sources, an ENVI `.hdr`, a world
/// file, a `.prj`, the `.aux.xml` that holds a PNG's georeferencing); for a name inside
/// an archive (`/vsizip/`, `/vsitar/`, `/vsigzip/`, `/vsi7z/`, `/vsirar/`), the archive.
/// Writing over any of them would change or destroy the input. Only `path` itself when
/// GDAL cannot open it; names that are not local files (`/vsicurl/`, `/vsimem/`) and files
/// that do not exist are left out.
pub fn input_files(path: &Path) -> Vec<PathBuf> {
    let mut names = Vec::new();
    if let Ok(dataset) = crate::read::open_dataset(path) {
        // SAFETY: GDALGetFileList returns a NULL-terminated array of NUL-terminated
        // strings (or NULL) owned by the caller, freed once with CSLDestroy after it is
        // copied; the dataset outlives the call.
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
    }
    names.push(path.to_string_lossy().into_owned());
    let mut files: Vec<PathBuf> = names
        .iter()
        .filter_map(|name| std::fs::canonicalize(on_disk(name)).ok())
        .collect();
    files.sort();
    files.dedup();
    files
}

/// The local file GDAL reads for `name`: `name` itself, or for a path inside an archive
/// (`/vsizip/a.zip/b.tif`, `/vsizip/{a.zip}/b.tif`, `/vsigzip/a.tif.gz`) the archive: the
/// shortest leading part of the path that is a regular file.
fn on_disk(name: &str) -> PathBuf {
    const ARCHIVES: [&str; 5] = ["/vsizip/", "/vsitar/", "/vsigzip/", "/vsi7z/", "/vsirar/"];
    let Some(inner) = ARCHIVES.iter().find_map(|p| name.strip_prefix(p)) else {
        return PathBuf::from(name);
    };
    if let Some(braced) = inner.strip_prefix('{') {
        if let Some((archive, _)) = braced.split_once('}') {
            return on_disk(archive);
        }
    }
    let inner = on_disk(inner);
    // Ancestors run from the whole path to its root: the last file among them.
    let archive = inner.ancestors().filter(|p| p.is_file()).last();
    archive.map_or_else(|| inner.clone(), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_in_an_archive_is_the_archive() {
        let dir = tempfile::tempdir().unwrap();
        let zip = dir.path().join("a.zip");
        std::fs::write(&zip, b"not really").unwrap();
        let z = zip.display();
        assert_eq!(on_disk(&format!("/vsizip/{z}/dem/b.tif")), zip);
        assert_eq!(on_disk(&format!("/vsizip/{{{z}}}/b.tif")), zip);
        assert_eq!(on_disk(&format!("/vsigzip/{z}")), zip);
        assert_eq!(on_disk(&format!("/vsigzip//vsizip/{z}/b.gz")), zip);
        assert_eq!(
            on_disk("/vsicurl/https://x/y.tif"),
            PathBuf::from("/vsicurl/https://x/y.tif")
        );
        assert_eq!(on_disk("plain.tif"), PathBuf::from("plain.tif"));
    }
}
