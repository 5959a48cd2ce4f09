//! A coarse look at a band, for planning work over it: where it has data, read at a few
//! hundred cells a side (from GDAL's overviews where the file has them).

use std::path::Path;

use crate::error::{gdal_reason, Error, Result};
use crate::read::{MaskSource, OpenBand};

/// At most `side x side` cells over the whole band, each the sample GDAL picks for it
/// (nearest, from the overview closest in size), with where each cell's centre lies.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// Cells across.
    pub width: usize,
    /// Cells down (row 0 at the top, as the raster's).
    pub height: usize,
    /// The cells' heights, scale and offset applied; NaN where the sample is nodata.
    pub values: Vec<f32>,
    /// Each cell centre's WGS84 longitude and latitude in degrees (NaN where PROJ cannot
    /// transform it), row-major as `values`.
    pub centres: Vec<[f64; 2]>,
}

/// The coverage of band `band` of `path` at most `side` cells a side.
///
/// The same file and GDAL give the same cells on every machine: they depend on the band's
/// size, its overviews and `side` only.
///
/// # Errors
/// As [`crate::open_info`]; [`Error::NotGeoreferenced`] without a CRS or geotransform;
/// [`Error::Read`] when GDAL fails.
pub fn coverage(path: &Path, band: usize, side: usize) -> Result<Coverage> {
    let opened = OpenBand::open(path, band)?;
    let info = opened.info.clone();
    let (Some(gt), Some(wkt)) = (info.geo_transform, info.crs_wkt.clone()) else {
        return Err(Error::NotGeoreferenced {
            path: path.to_path_buf(),
            missing: "a CRS and a geotransform",
            hint: "tiles need both; see `tinsmith info`",
        });
    };
    let Coarse {
        width: cw,
        height: ch,
        values,
        cell: (sx, sy),
    } = coarse_read(&opened, side)?;
    let mut points: Vec<[f64; 3]> = (0..ch)
        .flat_map(|j| {
            (0..cw).map(move |i| {
                let (px, py) = ((i as f64 + 0.5) * sx, (j as f64 + 0.5) * sy);
                [
                    gt[0] + px * gt[1] + py * gt[2],
                    gt[3] + px * gt[4] + py * gt[5],
                    0.0,
                ]
            })
        })
        .collect();
    if !crate::is_wgs84_lon_lat(&wkt) {
        crate::to_wgs84(&wkt, &mut points)?;
    }
    Ok(Coverage {
        width: cw,
        height: ch,
        values,
        centres: points.iter().map(|p| [p[0], p[1]]).collect(),
    })
}

/// A band read at most `side` cells a side: each cell the sample GDAL picks for it
/// (nearest, from the overview closest in size), NaN where it is nodata.
pub(crate) struct Coarse {
    /// Cells across.
    pub(crate) width: usize,
    /// Cells down (row 0 at the top).
    pub(crate) height: usize,
    /// Row-major heights, scale and offset applied.
    pub(crate) values: Vec<f32>,
    /// A cell's width and height in samples of the band.
    pub(crate) cell: (f64, f64),
}

/// Band `opened` read coarsely (see [`Coarse`]).
pub(crate) fn coarse_read(opened: &OpenBand, side: usize) -> Result<Coarse> {
    let info = &opened.info;
    let (path, band) = (info.path.as_path(), info.band);
    let (w, h) = (info.width as usize, info.height as usize);
    let scale = (w.max(h) as f64 / side.max(1) as f64).max(1.0);
    let (cw, ch) = (
        ((w as f64 / scale).ceil() as usize).max(1),
        ((h as f64 / scale).ceil() as usize).max(1),
    );
    let read_error = |e: gdal::errors::GdalError| Error::Read {
        path: path.to_path_buf(),
        band,
        reason: gdal_reason(&e, path),
        source: Box::new(e),
    };
    let rb = opened.band()?;
    let raw = rb
        .read_as::<f64>((0, 0), (w, h), (cw, ch), None)
        .map_err(read_error)?;
    let (_, raw) = raw.into_shape_and_vec();
    let mask = match opened.mask_source {
        None => None,
        Some(MaskSource::Gdal(_)) => Some(rb.open_mask_band().map_err(read_error)?),
        Some(MaskSource::Alpha(b)) => Some(opened.dataset().rasterband(b).map_err(read_error)?),
    };
    let valid = match mask {
        None => vec![true; cw * ch],
        Some(mask) => {
            let m = mask
                .read_as::<f64>((0, 0), (w, h), (cw, ch), None)
                .map_err(read_error)?;
            m.into_shape_and_vec().1.iter().map(|&v| v != 0.0).collect()
        }
    };
    let values = raw
        .iter()
        .zip(&valid)
        .map(|(&v, &ok)| {
            if !ok || !v.is_finite() || info.nodata.is_some_and(|nd| nd == v) {
                f32::NAN
            } else {
                (v * info.scale + info.offset) as f32
            }
        })
        .collect();
    Ok(Coarse {
        width: cw,
        height: ch,
        values,
        cell: (w as f64 / cw as f64, h as f64 / ch as f64),
    })
}
