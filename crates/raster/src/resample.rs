//! A raster put on another raster's grid: GDAL's warper, into a GeoTIFF the caller places.

use std::ffi::{CStr, CString};
use std::path::Path;

use crate::error::{Error, Result};
use crate::info::RasterInfo;
use crate::read::open_dataset;
use crate::reproject::same_crs;

/// How a value is taken from the source raster for each sample of the target grid
/// (GDAL's `-r`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Resampling {
    /// The source sample whose cell holds the target sample's centre: values are kept as
    /// they are (classes, codes).
    Nearest,
    /// Bilinear interpolation of the four nearest source samples (continuous values).
    #[default]
    Bilinear,
    /// Cubic convolution of the sixteen nearest source samples.
    Cubic,
    /// The mean of the source samples inside the target cell (a coarser target grid).
    Average,
}

impl Resampling {
    /// Every method, in the order the command line lists them.
    pub const ALL: [Resampling; 4] = [
        Resampling::Nearest,
        Resampling::Bilinear,
        Resampling::Cubic,
        Resampling::Average,
    ];

    /// GDAL's name for the method (`gdalwarp -r NAME`).
    pub fn name(self) -> &'static str {
        match self {
            Resampling::Nearest => "nearest",
            Resampling::Bilinear => "bilinear",
            Resampling::Cubic => "cubic",
            Resampling::Average => "average",
        }
    }
}

/// Whether `other` has exactly `grid`'s samples: the same size, geotransform (within a
/// billionth of a pixel) and CRS (or neither has a geotransform and the sizes agree).
pub fn on_same_grid(other: &RasterInfo, grid: &RasterInfo) -> bool {
    if (other.width, other.height) != (grid.width, grid.height) {
        return false;
    }
    match (other.geo_transform, grid.geo_transform) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            let pixel = b[1].abs().max(b[5].abs()).max(b[2].abs()).max(b[4].abs());
            let close = a
                .iter()
                .zip(&b)
                .all(|(x, y)| (x - y).abs() <= 1e-9 * pixel.max(1e-300));
            let crs = match (&other.crs_wkt, &grid.crs_wkt) {
                (Some(x), Some(y)) => same_crs(x, y),
                (None, None) => true,
                _ => false,
            };
            close && crs
        }
        _ => false,
    }
}

/// Writes `out`, a GeoTIFF with every band of the raster at `path` on `grid`'s samples: the
/// same size, geotransform and CRS, each value taken by `method` through GDAL's warper from
/// the source, in `Float64`, with the band's scale and offset applied to the values as
/// stored. Samples the source does not cover, or covers only with nodata, are nodata (NaN).
/// The values are `gdalwarp -te -ts -r METHOD -ot Float64 -dstnodata nan`'s. `out` is the
/// caller's to place and remove (a temporary file: it is as large as the grid in `f64` per
/// band).
///
/// Not a virtual (VRT) raster: GDAL 3.6 resamples a warped VRT with bilinear or cubic
/// kernels differently from `gdalwarp` to a file (up to 105 m apart on the bundled DEM put
/// through EPSG:4326 and back), and a file keeps the values `gdalwarp` users know.
///
pub fn resample_onto(path: &Path, grid: &RasterInfo, method: Resampling, out: &Path) -> Result<()> {
    let refuse = |reason: String| Error::Resample {
        path: path.to_path_buf(),
        target: grid.path.clone(),
        reason,
    };
    let source = open_dataset(path)?;
    let Some(gt) = grid.geo_transform else {
        return Err(refuse(
            "the target has no geotransform to place samples by".into(),
        ));
    };
    if gt[2] != 0.0 || gt[4] != 0.0 {
        return Err(refuse("the target's geotransform is rotated".into()));
    }
    let source_crs = source.spatial_ref().ok().and_then(|s| s.to_wkt().ok());
    let mut args: Vec<String> = [
        "-of",
        "GTiff",
        "-co",
        "TILED=YES",
        "-co",
        "BIGTIFF=IF_SAFER",
    ]
    .map(String::from)
    .to_vec();
    match (&source_crs, &grid.crs_wkt) {
        (Some(_), Some(target)) => args.extend(["-t_srs".into(), target.clone()]),
        (None, None) => {}
        (None, Some(_)) => return Err(refuse("it has no CRS and the target has one".into())),
        (Some(_), None) => return Err(refuse("it has a CRS and the target has none".into())),
    }
    let (w, h) = (f64::from(grid.width), f64::from(grid.height));
    let (x0, x1) = (gt[0], gt[0] + gt[1] * w);
    let (y0, y1) = (gt[3], gt[3] + gt[5] * h);
    args.extend([
        "-te".into(),
        format!("{:?}", x0.min(x1)),
        format!("{:?}", y0.min(y1)),
        format!("{:?}", x0.max(x1)),
        format!("{:?}", y0.max(y1)),
        "-ts".into(),
        grid.width.to_string(),
        grid.height.to_string(),
        "-r".into(),
        method.name().into(),
        "-ot".into(),
        "Float64".into(),
        "-dstnodata".into(),
        "nan".into(),
        "-wo".into(),
        "INIT_DEST=NO_DATA".into(),
    ]);
    // Scale and offset: the warper copies raw values; the file's bands get the source's.
    let scales: Vec<(f64, f64)> = (1..=source.raster_count())
        .map(|b| {
            let band = source.rasterband(b).ok();
            let scale = band.as_ref().and_then(|rb| rb.scale()).unwrap_or(1.0);
            let offset = band.as_ref().and_then(|rb| rb.offset()).unwrap_or(0.0);
            (scale, offset)
        })
        .collect();
    let c_args: Vec<CString> = args
        .iter()
        .map(|a| {
            CString::new(a.as_str()).map_err(|_| refuse(format!("argument {a:?} holds a NUL")))
        })
        .collect::<Result<_>>()?;
    let mut argv: Vec<*mut std::ffi::c_char> =
        c_args.iter().map(|a| a.as_ptr().cast_mut()).collect();
    argv.push(std::ptr::null_mut());
    let c_out = CString::new(out.to_string_lossy().as_bytes())
        .map_err(|_| refuse(format!("{} holds a NUL", out.display())))?;
    // SAFETY: argv is a NULL-terminated array of C strings that outlive the call; the
    // source dataset handle is valid while `source` lives; the options are freed once.
    #[allow(unsafe_code)]
    let (out, usage_error) = unsafe {
        let options = gdal_sys::GDALWarpAppOptionsNew(argv.as_mut_ptr(), std::ptr::null_mut());
        if options.is_null() {
            return Err(refuse(last_gdal_message()));
        }
        let mut handle = source.c_dataset();
        let mut usage_error = 0;
        let out = gdal_sys::GDALWarp(
            c_out.as_ptr(),
            std::ptr::null_mut(),
            1,
            &mut handle,
            options,
            &mut usage_error,
        );
        gdal_sys::GDALWarpAppOptionsFree(options);
        (out, usage_error)
    };
    if out.is_null() || usage_error != 0 {
        return Err(refuse(last_gdal_message()));
    }
    // SAFETY: `out` is the dataset GDALWarp returned, owned here and closed once (which
    // writes the file with the scales set on its bands).
    #[allow(unsafe_code)]
    unsafe {
        for (i, &(scale, offset)) in scales.iter().enumerate() {
            let band = gdal_sys::GDALGetRasterBand(out, i as i32 + 1);
            if !band.is_null() && (scale, offset) != (1.0, 0.0) {
                gdal_sys::GDALSetRasterScale(band, scale);
                gdal_sys::GDALSetRasterOffset(band, offset);
            }
        }
        gdal_sys::GDALClose(out);
    }
    Ok(())
}

/// GDAL's last error message, or a plain word when it left none.
fn last_gdal_message() -> String {
    // SAFETY: CPLGetLastErrorMsg returns a thread-local C string valid until the next
    // GDAL call on this thread; it is copied at once.
    #[allow(unsafe_code)]
    let msg = unsafe { CStr::from_ptr(gdal_sys::CPLGetLastErrorMsg()) }
        .to_string_lossy()
        .trim()
        .to_owned();
    if msg.is_empty() {
        "GDAL's warper failed".into()
    } else {
        msg
    }
}
