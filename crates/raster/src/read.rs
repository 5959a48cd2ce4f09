//! Opening a raster with GDAL and reading one band, strip by strip, into heights.

use std::io;
use std::path::Path;

use gdal::raster::{ColorInterpretation, RasterBand};
use gdal::spatial_ref::SpatialRef;
use gdal::{Dataset, DatasetOptions, GdalOpenFlags, Metadata};
use tinsmith_georef::Samples;

use crate::datum::{HeightShift, VerticalDatum};
use crate::decode::{SampleDecoder, SampleType, Stats};
use crate::error::{gdal_reason, Error, Result};
use crate::info::{Raster, RasterInfo};

/// Samples read per GDAL call (about 8 MB of `f64`), rounded to whole rows of blocks.
const STRIP_SAMPLES: usize = 1 << 20;

/// Opens band `band` (1-based) of the raster at `path` and returns its metadata and the
/// statistics of its samples (valid and nodata counts, min and max).
///
/// Reads the whole band, one strip of rows at a time, but keeps no samples: this works for
/// rasters too large for one [`Samples`]. A band without any valid sample is not an error here
/// (`valid_samples == 0`, `min` and `max` are `None`).
///
/// # Errors
/// [`Error::NotFound`], [`Error::NotARaster`], [`Error::BandOutOfRange`],
/// [`Error::UnsupportedType`] and [`Error::Read`], each naming `path`.
pub fn open_info(path: &Path, band: usize) -> Result<RasterInfo> {
    open_info_with_progress(path, band, &mut |_, _| {})
}

/// [`open_info`], calling `progress(rows_scanned, rows)` after each strip of rows, so that
/// a long scan of a large raster can show how far it is.
///
/// # Errors
/// As [`open_info`].
pub fn open_info_with_progress(
    path: &Path,
    band: usize,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RasterInfo> {
    open_info_on(path, band, &VerticalDatum::Ellipsoid, progress)
}

/// [`open_info_with_progress`] of the heights above the WGS84 ellipsoid that the band's
/// heights above `datum` are (see [`read_samples_on`]): the statistics are those of the
/// converted heights, and [`RasterInfo::converted_from`] says so. With
/// [`VerticalDatum::Ellipsoid`] the band's own heights.
///
/// # Errors
/// As [`open_info`], plus [`Error::VerticalDatum`] and [`Error::Crs`] as
/// [`read_samples_on`].
pub fn open_info_on(
    path: &Path,
    band: usize,
    datum: &VerticalDatum,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RasterInfo> {
    let opened = OpenBand::open(path, band)?.converting(datum)?;
    let rb = opened.band()?;
    let mut stats = Stats::default();
    let mut buf = Vec::new();
    let height = u64::from(opened.info.height);
    for (y0, rows) in opened.strips(&rb) {
        buf.resize(rows * opened.width(), 0.0);
        opened.read_strip(&rb, y0, rows, &mut buf)?;
        stats.add(&buf);
        progress((y0 + rows) as u64, height);
    }
    Ok(opened.finish(stats))
}

/// Reads band `band` (1-based) of the raster at `path` into [`Samples`] of heights.
///
/// Every sample type GDAL has for real numbers is accepted (Byte, Int8, UInt16, Int16,
/// UInt32, Int32, UInt64, Int64, Float32, Float64; 64-bit integers beyond 2^53 lose
/// precision). A sample becomes NaN (nodata) when it is NaN or infinite, or when it equals
/// the band's nodata value compared in the band's own type: a Float32 band's nodata value is
/// rounded to `f32` first (so `-3.4e38` declared in text matches the stored `f32`), an integer
/// band's is rounded to the nearest integer and matches nothing when the type cannot hold it.
/// Valid samples are mapped through the band's scale and offset, if any. GDAL mask bands
/// are not consulted. The returned [`RasterInfo`] has the statistics of the samples.
///
/// # Errors
/// As [`open_info`], plus [`Error::TooLarge`] (checked before any sample is read) and
/// [`Error::AllNodata`] when no sample is valid.
pub fn read_samples(path: &Path, band: usize) -> Result<Raster> {
    read_samples_on(path, band, &VerticalDatum::Ellipsoid)
}

/// [`read_samples`], turning heights above `datum` (a geoid: most DEMs hold orthometric
/// heights) into heights above the WGS84 ellipsoid: each valid sample gains the geoid's
/// height at its centre, placed through the raster's CRS and geotransform and
/// interpolated by PROJ from the geoid's grid. Windows and strips of the same raster read
/// with the same datum ([`crate::WindowReader::open_on`], [`open_info_on`]) give the same
/// values sample for sample. With [`VerticalDatum::Ellipsoid`] this is [`read_samples`].
///
/// # Errors
/// As [`read_samples`], plus [`Error::VerticalDatum`] when the raster has no CRS or
/// geotransform, or the geoid's grid is missing or does not cover a sample, and
/// [`Error::Crs`] when PROJ cannot take a sample to WGS84.
pub fn read_samples_on(path: &Path, band: usize, datum: &VerticalDatum) -> Result<Raster> {
    let opened = OpenBand::open(path, band)?.converting(datum)?;
    let (width, height) = (opened.info.width, opened.info.height);
    let samples = width as u64 * height as u64;
    if samples >= u32::MAX as u64 {
        return Err(Error::TooLarge {
            path: path.to_path_buf(),
            width: width as usize,
            height: height as usize,
        });
    }
    let rb = opened.band()?;
    let mut values = vec![0.0; samples as usize];
    let mut stats = Stats::default();
    for (y0, rows) in opened.strips(&rb) {
        let strip = &mut values[y0 * opened.width()..(y0 + rows) * opened.width()];
        opened.read_strip(&rb, y0, rows, strip)?;
        stats.add(strip);
    }
    if stats.valid == 0 {
        return Err(Error::AllNodata {
            path: path.to_path_buf(),
            band,
        });
    }
    let samples = Samples::new(width, height, values).map_err(|source| Error::Grid {
        path: path.to_path_buf(),
        band,
        source,
    })?;
    Ok(Raster {
        samples,
        info: opened.finish(stats),
    })
}

/// Reads the `size` window at `at` of `rb` as `T` into `dst`, widened by `widen`.
fn read_widened<T: gdal::raster::GdalType + Copy + Default>(
    rb: &RasterBand<'_>,
    at: (isize, isize),
    size: (usize, usize),
    dst: &mut [f64],
    widen: fn(T) -> f64,
) -> gdal::errors::Result<()> {
    let mut native = vec![T::default(); dst.len()];
    rb.read_into_slice::<T>(at, size, size, &mut native, None)?;
    for (d, &n) in dst.iter_mut().zip(&native) {
        *d = widen(n);
    }
    Ok(())
}

/// An open dataset with a checked band and everything known before reading samples.
pub(crate) struct OpenBand {
    dataset: Dataset,
    /// Metadata; the statistics are still zero.
    pub(crate) info: RasterInfo,
    decoder: SampleDecoder,
    /// GDAL's name of the band's type (`Byte` for a signed Byte band too), read as such.
    gdal_type: String,
    pub(crate) mask_source: Option<MaskSource>,
    /// Heights above a geoid turned into ellipsoidal heights as they are read.
    shift: Option<HeightShift>,
}

/// Where the band's validity mask comes from, besides its nodata value.
#[derive(Debug, Clone, Copy)]
pub(crate) enum MaskSource {
    /// GDAL's mask band (per-dataset, per-band or a Byte alpha band), of this kind.
    Gdal(&'static str),
    /// An alpha band (by number) of a type GDAL does not take as a mask.
    Alpha(usize),
}

impl OpenBand {
    pub(crate) fn open(path: &Path, band: usize) -> Result<OpenBand> {
        let dataset = open_dataset(path)?;
        let count = dataset.raster_count();
        if count == 0 {
            // A container (netCDF, HDF5, GeoPackage...) whose rasters are its subdatasets
            // (some drivers list them whole but do not answer for one item).
            let names: Vec<String> = dataset
                .metadata_domain("SUBDATASETS")
                .unwrap_or_default()
                .into_iter()
                .filter_map(|item| {
                    let (key, value) = item.split_once('=')?;
                    key.ends_with("_NAME").then(|| value.to_owned())
                })
                .collect();
            if let Some(first) = names.first() {
                return Err(Error::Subdatasets {
                    path: path.to_path_buf(),
                    count: names.len(),
                    first: first.clone(),
                });
            }
        }
        if band == 0 || band > count {
            return Err(Error::BandOutOfRange {
                path: path.to_path_buf(),
                band,
                count,
            });
        }
        let (w, h) = dataset.raster_size();
        let (Ok(width), Ok(height)) = (u32::try_from(w), u32::try_from(h)) else {
            return Err(Error::TooLarge {
                path: path.to_path_buf(),
                width: w,
                height: h,
            });
        };

        let rb = dataset.rasterband(band).map_err(|source| Error::Read {
            path: path.to_path_buf(),
            band,
            reason: gdal_reason(&source, path),
            source: Box::new(source),
        })?;
        let gdal_type = rb.band_type().name();
        let pixel_type = rb.metadata_item("PIXELTYPE", "IMAGE_STRUCTURE");
        let Some(sample_type) = SampleType::from_gdal(&gdal_type, pixel_type.as_deref()) else {
            return Err(Error::UnsupportedType {
                path: path.to_path_buf(),
                band,
                data_type: gdal_type,
            });
        };
        // A mask GDAL keeps besides nodata (an alpha band, a per-dataset or per-band mask,
        // as gdalwarp -dstalpha or gdal_translate -mask write): its zeros are nodata too.
        // GDAL counts an alpha band as a mask only when it is Byte (or UInt16); gdalwarp
        // uses one of any type, and so do we.
        let alpha_band = (1..=count).find(|&b| {
            b != band
                && dataset
                    .rasterband(b)
                    .is_ok_and(|a| a.color_interpretation() == ColorInterpretation::AlphaBand)
        });
        let mask_source = match rb.mask_flags() {
            Ok(flags) if !flags.is_all_valid() && !flags.is_nodata() => {
                Some(MaskSource::Gdal(if flags.is_alpha() {
                    "alpha band"
                } else if flags.is_per_dataset() {
                    "per-dataset mask"
                } else {
                    "mask band"
                }))
            }
            _ => alpha_band.map(MaskSource::Alpha),
        };
        let mask = mask_source.map(|m| match m {
            MaskSource::Gdal(kind) => kind.to_owned(),
            MaskSource::Alpha(b) => format!("alpha band {b}"),
        });
        // The 64-bit integer types have their own getters (the f64 one warns on stderr).
        let nodata = match gdal_type.as_str() {
            "Int64" => rb.no_data_value_i64().map(|v| v as f64),
            "UInt64" => rb.no_data_value_u64().map(|v| v as f64),
            _ => rb.no_data_value(),
        };
        let scale = rb.scale().filter(|s| s.is_finite()).unwrap_or(1.0);
        let offset = rb.offset().filter(|o| o.is_finite()).unwrap_or(0.0);
        let decoder = SampleDecoder::new(sample_type, nodata, scale, offset);
        let data_type = sample_type.display_name(&gdal_type);
        let description = rb.description().ok().filter(|d| !d.trim().is_empty());

        let srs = dataset.spatial_ref().ok();
        let crs_wkt = srs
            .as_ref()
            .and_then(|s| s.to_wkt().ok())
            .filter(|w| !w.is_empty());
        let epsg = srs.and_then(epsg_code);
        // GDAL fails (and fills in an identity) when the dataset has no geotransform.
        let geo_transform = dataset.geo_transform().ok();
        let gcp_count = dataset.gcps().len();
        let geolocation = dataset.metadata_domain("GEOLOCATION").is_some();

        let info = RasterInfo {
            path: path.to_path_buf(),
            driver: dataset.driver().short_name(),
            width,
            height,
            band_count: count,
            band,
            description,
            data_type,
            nodata,
            scale,
            offset,
            crs_wkt,
            epsg,
            geo_transform,
            gcp_count,
            geolocation,
            mask,
            valid_samples: 0,
            nodata_samples: 0,
            min: None,
            max: None,
            integral_heights: false,
            converted_from: None,
        };
        Ok(OpenBand {
            dataset,
            info,
            decoder,
            gdal_type,
            mask_source,
            shift: None,
        })
    }

    /// The band with its heights above `datum` read as heights above the WGS84
    /// ellipsoid (see [`read_samples_on`]); unchanged for the ellipsoid.
    pub(crate) fn converting(mut self, datum: &VerticalDatum) -> Result<OpenBand> {
        self.shift = HeightShift::new(&self.info, datum)?;
        if self.shift.is_some() {
            self.info.converted_from = Some(datum.clone());
            // The heights are no longer in the raster's vertical CRS, if it declares one.
            if let Some(wkt) = self.info.crs_wkt.as_deref() {
                let horizontal = crate::horizontal_crs(wkt);
                if horizontal != wkt {
                    self.info.epsg = gdal::spatial_ref::SpatialRef::from_wkt(&horizontal)
                        .ok()
                        .and_then(epsg_code);
                    self.info.crs_wkt = Some(horizontal);
                }
            }
        }
        Ok(self)
    }

    pub(crate) fn dataset(&self) -> &Dataset {
        &self.dataset
    }

    fn width(&self) -> usize {
        self.info.width as usize
    }

    /// Drops the blocks GDAL has cached for this dataset (its cache is process-wide and
    /// would otherwise keep every block read until it is full).
    pub(crate) fn release_cached_blocks(&mut self) -> Result<()> {
        let flushed = self.dataset.flush_cache();
        flushed.map_err(|e| self.read_error(e))
    }

    pub(crate) fn band(&self) -> Result<RasterBand<'_>> {
        self.dataset
            .rasterband(self.info.band)
            .map_err(|e| self.read_error(e))
    }

    /// Reads the `size.0` x `size.1` window whose top-left sample is `origin` into `dst`
    /// (row-major) and decodes it in place; the window must lie inside the raster.
    pub(crate) fn read_window(
        &self,
        rb: &RasterBand<'_>,
        origin: (usize, usize),
        size: (usize, usize),
        dst: &mut [f64],
    ) -> Result<()> {
        let at = (origin.0 as isize, origin.1 as isize);
        // Read as the band's own type, then widened: GDAL computes some bands (a VRT that
        // scales its source) for the buffer's type, so an f64 read can give other values
        // than every reader of the band's type (gdal_translate, rasterio) sees.
        let read = match self.gdal_type.as_str() {
            // A signed Byte band too: the decoder reinterprets 128..=255.
            "Byte" => read_widened::<u8>(rb, at, size, dst, f64::from),
            "UInt16" => read_widened::<u16>(rb, at, size, dst, f64::from),
            "Int16" => read_widened::<i16>(rb, at, size, dst, f64::from),
            "UInt32" => read_widened::<u32>(rb, at, size, dst, f64::from),
            "Int32" => read_widened::<i32>(rb, at, size, dst, f64::from),
            // Beyond 2^53 they round to the nearest f64, as the decoder documents.
            "UInt64" => read_widened::<u64>(rb, at, size, dst, |v| v as f64),
            "Int64" => read_widened::<i64>(rb, at, size, dst, |v| v as f64),
            "Float32" => read_widened::<f32>(rb, at, size, dst, f64::from),
            _ => rb.read_into_slice::<f64>(at, size, size, dst, None),
        };
        read.map_err(|e| self.read_error(e))?;
        for v in dst.iter_mut() {
            *v = self.decoder.decode(*v);
        }
        if let Some(source) = self.mask_source {
            let mask = match source {
                MaskSource::Gdal(_) => rb.open_mask_band(),
                MaskSource::Alpha(b) => self.dataset.rasterband(b),
            }
            .map_err(|e| self.read_error(e))?;
            let mut valid = vec![0u8; dst.len()];
            mask.read_into_slice::<u8>(
                (origin.0 as isize, origin.1 as isize),
                size,
                size,
                &mut valid,
                None,
            )
            .map_err(|e| self.read_error(e))?;
            for (v, &m) in dst.iter_mut().zip(&valid) {
                if m == 0 {
                    *v = f64::NAN;
                }
            }
        }
        if let Some(shift) = &self.shift {
            shift.apply(origin, size, dst)?;
        }
        Ok(())
    }

    /// `(first row, row count)` of each strip, top to bottom; strips are whole rows of blocks.
    fn strips(&self, rb: &RasterBand<'_>) -> impl Iterator<Item = (usize, usize)> {
        let height = self.info.height as usize;
        let block_rows = rb.block_size().1.clamp(1, height.max(1));
        let blocks = (STRIP_SAMPLES / (self.width().max(1) * block_rows)).max(1);
        let step = block_rows * blocks;
        (0..height)
            .step_by(step)
            .map(move |y0| (y0, step.min(height - y0)))
    }

    /// Reads `rows` rows from `y0` into `dst` (row-major) and decodes them in place.
    fn read_strip(
        &self,
        rb: &RasterBand<'_>,
        y0: usize,
        rows: usize,
        dst: &mut [f64],
    ) -> Result<()> {
        self.read_window(rb, (0, y0), (self.width(), rows), dst)
    }

    fn read_error(&self, source: gdal::errors::GdalError) -> Error {
        Error::Read {
            path: self.info.path.clone(),
            band: self.info.band,
            reason: gdal_reason(&source, &self.info.path),
            source: Box::new(source),
        }
    }

    fn finish(self, stats: Stats) -> RasterInfo {
        RasterInfo {
            valid_samples: stats.valid,
            nodata_samples: stats.nodata,
            min: stats.min,
            max: stats.max,
            integral_heights: stats.valid > 0 && !stats.fractional,
            ..self.info
        }
    }
}

/// Opens `path` read-only with GDAL's raster drivers, asking GDAL to say why it cannot.
pub(crate) fn open_dataset(path: &Path) -> Result<Dataset> {
    if path.to_str().is_none() && path.exists() {
        return Err(Error::NameNotUtf8 {
            path: path.to_path_buf(),
        });
    }
    if is_missing_file(path) {
        return Err(Error::NotFound {
            path: path.to_path_buf(),
        });
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        // GDAL would block reading a FIFO with no writer, and seeks where there is none;
        // a character device (`/dev/zero`, a terminal) has no size and no raster either.
        if let Ok(kind) = std::fs::metadata(path).map(|m| m.file_type()) {
            if kind.is_fifo() || kind.is_socket() || kind.is_char_device() {
                return Err(Error::NotAFile {
                    path: path.to_path_buf(),
                });
            }
        }
    }
    crate::quiet::silence_hdf5_on_this_thread();
    let options = DatasetOptions {
        open_flags: GdalOpenFlags::GDAL_OF_RASTER
            | GdalOpenFlags::GDAL_OF_READONLY
            | GdalOpenFlags::GDAL_OF_VERBOSE_ERROR,
        ..Default::default()
    };
    let opened = Dataset::open_ex(path, options);
    if let Ok(dataset) = &opened {
        crate::quiet::note_driver(&dataset.driver().short_name());
    }
    opened.map_err(|source| {
        let reason = gdal_reason(&source, path);
        let reason = match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => format!("a directory: {reason}"),
            Ok(m) if m.is_file() && m.len() == 0 => format!("an empty file: {reason}"),
            _ => reason,
        };
        Error::NotARaster {
            path: path.to_path_buf(),
            reason,
            source: Box::new(source),
        }
    })
}

/// Whether `path` is a plain file system path at which nothing exists. GDAL's virtual file
/// systems (`/vsizip/...`) and connection strings (`NETCDF:file.nc:var`) are left to GDAL.
fn is_missing_file(path: &Path) -> bool {
    let text = path.to_string_lossy();
    if text.starts_with("/vsi") || has_driver_prefix(&text) {
        return false;
    }
    match std::fs::metadata(path) {
        Ok(_) => false,
        Err(e) => matches!(
            e.kind(),
            io::ErrorKind::NotFound | io::ErrorKind::NotADirectory
        ),
    }
}

/// Whether `text` starts like a GDAL connection string, `NAME:` with a name of two or more
/// letters, digits or underscores (a Windows drive letter has one).
fn has_driver_prefix(text: &str) -> bool {
    text.split_once(':').is_some_and(|(name, _)| {
        name.len() >= 2 && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
    })
}

/// The EPSG code of `srs`: its own authority code if that is EPSG, else a code that GDAL's
/// auto-identification or, failing that, its matcher (PROJ's identification, which reads
/// ESRI's `.prj` names) finds for it, if that code's CRS is the same CRS (GDAL names a UTM
/// zone in feet or kilometres by the zone's code in metres); `None` otherwise (e.g. a
/// compound CRS "unknown").
fn epsg_code(srs: SpatialRef) -> Option<u32> {
    if let Some(code) = epsg_authority(&srs) {
        return Some(code);
    }
    let same = |code: u32| {
        SpatialRef::from_epsg(code)
            .is_ok_and(|candidate| crate::reproject::equivalent(&candidate, &srs))
    };
    let mut identified = srs.clone();
    let auto = identified
        .auto_identify_epsg()
        .ok()
        .and_then(|()| epsg_authority(&identified));
    auto.filter(|&code| same(code))
        .or_else(|| epsg_matches(&srs).into_iter().find(|&code| same(code)))
}

/// The code of `srs`'s own authority, if that is EPSG.
fn epsg_authority(srs: &SpatialRef) -> Option<u32> {
    let name = srs.auth_name()?;
    if !name.eq_ignore_ascii_case("EPSG") {
        return None;
    }
    u32::try_from(srs.auth_code().ok()?).ok()
}

/// The EPSG codes GDAL's `OSRFindMatches` offers for `srs`, best first.
fn epsg_matches(srs: &SpatialRef) -> Vec<u32> {
    let mut count = 0;
    let mut confidence = std::ptr::null_mut();
    // SAFETY: `srs` is a live handle; OSRFindMatches returns NULL or an array of `count`
    // owned handles, freed with OSRFreeSRSArray, and a CPLMalloc'd array of confidences.
    #[allow(unsafe_code)]
    unsafe {
        let matches = gdal_sys::OSRFindMatches(
            srs.to_c_hsrs(),
            std::ptr::null_mut(),
            &mut count,
            &mut confidence,
        );
        let mut codes = Vec::new();
        if !matches.is_null() {
            for i in 0..usize::try_from(count).unwrap_or(0) {
                let candidate = *matches.add(i);
                if candidate.is_null() {
                    continue;
                }
                if let Ok(candidate) = SpatialRef::from_c_obj(candidate) {
                    codes.extend(epsg_authority(&candidate));
                }
            }
            gdal_sys::OSRFreeSRSArray(matches);
        }
        gdal_sys::VSIFree(confidence.cast());
        codes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn connection_strings_are_left_to_gdal() {
        assert!(has_driver_prefix("NETCDF:foo.nc:z"));
        assert!(has_driver_prefix("GTIFF_DIR:1:a.tif"));
        assert!(!has_driver_prefix("C:\\dem.tif"));
        assert!(!has_driver_prefix("dir/a:b.tif"));
        assert!(!has_driver_prefix("dem.tif"));
        assert!(!is_missing_file(Path::new("/vsimem/nothing.tif")));
        assert!(!is_missing_file(Path::new("HDF5:missing.h5://x")));
    }

    #[test]
    fn plain_missing_paths_are_detected() {
        let dir = tempfile::tempdir().expect("tempdir");
        assert!(is_missing_file(&dir.path().join("absent.tif")));
        assert!(is_missing_file(&dir.path().join("absent/deeper.tif")));
        assert!(!is_missing_file(dir.path()));
    }

    #[test]
    fn epsg_of_plain_and_unidentifiable_crs() {
        let srs = SpatialRef::from_epsg(32632).expect("EPSG:32632");
        assert_eq!(epsg_code(srs), Some(32632));
        let srs = SpatialRef::from_proj4(
            "+proj=tmerc +lat_0=0 +lon_0=7.3 +k=1 +x_0=0 +y_0=0 +ellps=bessel",
        )
        .expect("proj4");
        assert_eq!(epsg_code(srs), None);
        // A UTM zone without its code (as GDAL reads `gdalwarp -t_srs "+proj=utm +zone=32
        // +datum=WGS84 +units=us-ft"`'s GeoTIFF) is identified by the zone, in metres or not.
        let utm = |false_easting: &str, unit: &str| {
            format!(
                "PROJCS[\"unknown\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",\
                 6378137,298.257223563,AUTHORITY[\"EPSG\",\"7030\"]],AUTHORITY[\"EPSG\",\"6326\"]],\
                 PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\
                 \"9122\"]],AUTHORITY[\"EPSG\",\"4326\"]],PROJECTION[\"Transverse_Mercator\"],\
                 PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",9],\
                 PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",{false_easting}],\
                 PARAMETER[\"false_northing\",0],{unit},AXIS[\"Easting\",EAST],\
                 AXIS[\"Northing\",NORTH]]"
            )
        };
        // ESRI's spelling (a `.prj` beside an ESRI ASCII grid), which only the matcher reads.
        let esri = "PROJCS[\"WGS_1984_UTM_Zone_32N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",\
            SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],\
            UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],\
            PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],\
            PARAMETER[\"Central_Meridian\",9.0],PARAMETER[\"Scale_Factor\",0.9996],\
            PARAMETER[\"Latitude_Of_Origin\",0.0],UNIT[\"Meter\",1.0]]";
        let srs = SpatialRef::from_esri(esri).expect("ESRI WKT");
        assert_eq!(epsg_code(srs), Some(32632));
        let esri_wgs84 = "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",\
            6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"Degree\",0.017453292519943295]]";
        let srs = SpatialRef::from_esri(esri_wgs84).expect("ESRI WKT");
        assert_eq!(epsg_code(srs), Some(4326));
        let metres = utm("500000", "UNIT[\"metre\",1]");
        let srs = SpatialRef::from_wkt(&metres).expect("WKT");
        assert_eq!(epsg_code(srs), Some(32632));
        for wkt in [
            utm(
                "1640416.66666667",
                "UNIT[\"US survey foot\",0.304800609601219]",
            ),
            utm("500", "UNIT[\"kilometre\",1000]"),
        ] {
            let srs = SpatialRef::from_wkt(&wkt).expect("WKT");
            let unit = wkt.split("UNIT").last().unwrap_or_default();
            assert_eq!(epsg_code(srs), None, "{unit}");
        }
    }
}
