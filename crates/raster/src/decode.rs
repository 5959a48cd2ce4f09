//! Turning raw band samples (read as `f64`) into heights: the nodata rule and scale/offset.

/// How a band stores its samples, as far as nodata matching is concerned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SampleType {
    /// An integer type whose values are the integers in `min..=max` (all exact in `f64`,
    /// except 64-bit integers beyond 2^53).
    Integer {
        /// Smallest representable value.
        min: f64,
        /// Largest representable value.
        max: f64,
    },
    /// A Byte band marked `PIXELTYPE=SIGNEDBYTE` (GDAL < 3.7's signed 8-bit): GDAL hands out
    /// 0..=255, which this type reinterprets as two's complement -128..=127.
    SignedByte,
    /// IEEE single precision.
    Float32,
    /// IEEE double precision.
    Float64,
}

impl SampleType {
    /// The sample type for a GDAL data type name (`GDALGetDataTypeName`) and the band's
    /// `PIXELTYPE` metadata item (domain `IMAGE_STRUCTURE`); `None` for complex or unknown
    /// types.
    pub(crate) fn from_gdal(name: &str, pixel_type: Option<&str>) -> Option<SampleType> {
        let int = |min: f64, max: f64| Some(SampleType::Integer { min, max });
        match name {
            "Byte" if pixel_type == Some("SIGNEDBYTE") => Some(SampleType::SignedByte),
            "Byte" => int(0.0, u8::MAX as f64),
            "Int8" => int(i8::MIN as f64, i8::MAX as f64),
            "UInt16" => int(0.0, u16::MAX as f64),
            "Int16" => int(i16::MIN as f64, i16::MAX as f64),
            "UInt32" => int(0.0, u32::MAX as f64),
            "Int32" => int(i32::MIN as f64, i32::MAX as f64),
            "UInt64" => int(0.0, u64::MAX as f64),
            "Int64" => int(i64::MIN as f64, i64::MAX as f64),
            "Float32" => Some(SampleType::Float32),
            "Float64" => Some(SampleType::Float64),
            _ => None,
        }
    }

    /// The name reported in [`crate::RasterInfo::data_type`]: GDAL's name, except that a
    /// signed Byte band is called `Int8` (what GDAL >= 3.7 calls it).
    pub(crate) fn display_name(self, gdal_name: &str) -> String {
        match self {
            SampleType::SignedByte => "Int8".to_string(),
            _ => gdal_name.to_string(),
        }
    }
}

/// Maps one raw sample (as GDAL converts it to `f64`) to a height, or to NaN for nodata.
///
/// A sample is nodata when it is NaN or infinite, or when it equals the band's nodata value
/// *in the band's own type*, by GDAL's rule: for Float32 bands the nodata value is first
/// rounded to `f32` (vinschgau declares `-3.4e38`, which is not `-FLT_MAX` and is stored as
/// the nearest `f32`), and float samples match within GDAL's tolerance (see
/// `gdal_real_equal`); for integer bands it matches only when it is an integer within the
/// type's range (otherwise no sample can hold it). Valid samples are then mapped through the
/// band's scale and offset (`value * scale + offset`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SampleDecoder {
    sample_type: SampleType,
    signed_byte: bool,
    /// The nodata value as the raw `f64` a nodata sample reads as; never NaN.
    nodata_key: Option<f64>,
    scale: f64,
    offset: f64,
}

impl SampleDecoder {
    /// A decoder for samples of `sample_type` with the band's declared `nodata`, `scale` and
    /// `offset` (non-finite scale or offset are ignored).
    pub(crate) fn new(
        sample_type: SampleType,
        nodata: Option<f64>,
        scale: f64,
        offset: f64,
    ) -> SampleDecoder {
        let nodata_key = nodata
            .filter(|v| !v.is_nan())
            .and_then(|nd| match sample_type {
                SampleType::Integer { min, max } => integer_key(nd, min, max),
                SampleType::SignedByte => integer_key(nd, i8::MIN as f64, i8::MAX as f64),
                SampleType::Float32 => Some(nd as f32 as f64),
                SampleType::Float64 => Some(nd),
            });
        SampleDecoder {
            sample_type,
            signed_byte: sample_type == SampleType::SignedByte,
            nodata_key,
            scale: if scale.is_finite() { scale } else { 1.0 },
            offset: if offset.is_finite() { offset } else { 0.0 },
        }
    }

    /// The height of a raw sample, or NaN when it is nodata.
    #[inline]
    pub(crate) fn decode(&self, raw: f64) -> f64 {
        let v = if self.signed_byte && raw >= 128.0 {
            raw - 256.0
        } else {
            raw
        };
        let nodata = match self.nodata_key {
            Some(key) if matches!(self.sample_type, SampleType::Float32 | SampleType::Float64) => {
                gdal_real_equal(self.sample_type, v, key)
            }
            key => Some(v) == key,
        };
        if !v.is_finite() || nodata {
            return f64::NAN;
        }
        v * self.scale + self.offset
    }
}

/// GDAL's test for a floating-point sample equal to the nodata value (`ARE_REAL_EQUAL` in
/// its nodata mask band and statistics): equal, or closer than two `f32` epsilons of their
/// sum, computed in the band's own type. So a Float32 file that declares
/// `-3.4028230607370965e+38` (as ArcGIS writes) or `-3.4e38` while its samples hold
/// `-f32::MAX` has those samples as nodata, as `gdalinfo -stats` counts them: near
/// `±f32::MAX` the `f32` sum overflows to infinity and everything that far out matches.
fn gdal_real_equal(sample_type: SampleType, value: f64, nodata: f64) -> bool {
    if sample_type == SampleType::Float32 {
        let (a, b) = (value as f32, nodata as f32);
        a == b || (a - b).abs() < f32::EPSILON * (a + b).abs() * 2.0
    } else {
        value == nodata
            || (value - nodata).abs() < f64::from(f32::EPSILON) * (value + nodata).abs() * 2.0
    }
}

/// The integer an integer band stores for nodata value `nd`: none when the value is not an
/// integer or the type cannot hold it (no sample can equal it; `gdalinfo -stats` counts
/// no nodata then either).
fn integer_key(nd: f64, min: f64, max: f64) -> Option<f64> {
    (nd.fract() == 0.0 && nd >= min && nd <= max).then_some(nd)
}

/// Running counts and range of decoded samples.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Stats {
    pub(crate) valid: u64,
    pub(crate) nodata: u64,
    pub(crate) min: Option<f64>,
    pub(crate) max: Option<f64>,
    /// Some valid sample is not an integer.
    pub(crate) fractional: bool,
}

impl Stats {
    /// Adds decoded samples (NaN = nodata).
    pub(crate) fn add(&mut self, decoded: &[f64]) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut valid = 0u64;
        let mut fractional = false;
        for &v in decoded {
            if v.is_finite() {
                valid += 1;
                lo = lo.min(v);
                hi = hi.max(v);
                fractional |= v.fract() != 0.0;
            }
        }
        self.fractional |= fractional;
        self.valid += valid;
        self.nodata += decoded.len() as u64 - valid;
        if valid > 0 {
            self.min = Some(self.min.map_or(lo, |m| m.min(lo)));
            self.max = Some(self.max.map_or(hi, |m| m.max(hi)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ty(name: &str) -> SampleType {
        SampleType::from_gdal(name, None).expect("known type")
    }

    #[test]
    fn float32_nodata_is_matched_in_single_precision() {
        // vinschgau: nodata declared as -3.4e38 (not -FLT_MAX); the pixels hold the f32 nearest
        // to it, which as f64 is not -3.4e38.
        let stored = -3.4e38_f32 as f64;
        assert_ne!(stored, -3.4e38);
        let d = SampleDecoder::new(ty("Float32"), Some(-3.4e38), 1.0, 0.0);
        assert!(d.decode(stored).is_nan());
        // -FLT_MAX too, as gdalinfo -stats counts it (the f32 sum overflows), and so
        // everything that far out; ordinary heights are untouched.
        assert!(d.decode(f32::MIN as f64).is_nan());
        assert!(d.decode(-3.3e38_f32 as f64).is_nan());
        assert_eq!(d.decode(-1e30_f32 as f64), -1e30_f32 as f64);
        assert_eq!(d.decode(-9999.0), -9999.0);
        let d = SampleDecoder::new(ty("Float32"), Some(f32::MIN as f64), 1.0, 0.0);
        assert!(d.decode(f32::MIN as f64).is_nan());
        // ArcGIS-style: declared two f32 steps short of -FLT_MAX, samples hold -FLT_MAX
        // (GDAL's own rule treats them as nodata).
        let d = SampleDecoder::new(ty("Float32"), Some(-3.4028230607370965e38), 1.0, 0.0);
        assert!(d.decode(f32::MIN as f64).is_nan());
        assert_eq!(d.decode(-1e30_f32 as f64), -1e30_f32 as f64);
        let d = SampleDecoder::new(ty("Float32"), Some(3.4028230607370965e38), 1.0, 0.0);
        assert!(d.decode(f32::MAX as f64).is_nan());
        assert_eq!(d.decode(12.5), 12.5);
    }

    #[test]
    fn float64_nodata_matches_within_gdal_tolerance() {
        // GDAL's ARE_REAL_EQUAL: |a - b| < 2 f32 epsilons of |a + b| (0.0048 at -9999).
        let d = SampleDecoder::new(ty("Float64"), Some(-9999.0), 1.0, 0.0);
        assert!(d.decode(-9999.0).is_nan());
        assert!(d.decode(-9999.000001).is_nan());
        assert_eq!(d.decode(-9998.99), -9998.99);
        assert_eq!(d.decode(-3.4e38_f32 as f64), -3.4e38_f32 as f64);
    }

    #[test]
    fn non_finite_samples_are_nodata_whatever_the_declared_value() {
        for d in [
            SampleDecoder::new(ty("Float64"), None, 1.0, 0.0),
            SampleDecoder::new(ty("Float32"), Some(0.0), 1.0, 0.0),
        ] {
            assert!(d.decode(f64::NAN).is_nan());
            assert!(d.decode(f64::INFINITY).is_nan());
            assert!(d.decode(f64::NEG_INFINITY).is_nan());
        }
    }

    #[test]
    fn nan_nodata_matches_only_nan() {
        let d = SampleDecoder::new(ty("Float32"), Some(f64::NAN), 1.0, 0.0);
        assert!(d.decode(f64::NAN).is_nan());
        assert_eq!(d.decode(0.0), 0.0);
    }

    #[test]
    fn integer_nodata_must_be_an_integer_in_range() {
        let d = SampleDecoder::new(ty("Int16"), Some(-32768.0), 1.0, 0.0);
        assert!(d.decode(-32768.0).is_nan());
        assert_eq!(d.decode(-32767.0), -32767.0);
        // A nodata value the type cannot hold matches nothing.
        let d = SampleDecoder::new(ty("Byte"), Some(-9999.0), 1.0, 0.0);
        assert_eq!(d.decode(0.0), 0.0);
        assert_eq!(d.decode(255.0), 255.0);
        // Nor does one that is not an integer (GDAL 3.6's mask band would truncate 3.5 to 3;
        // its statistics and later versions match nothing).
        let d = SampleDecoder::new(ty("Int16"), Some(3.5), 1.0, 0.0);
        assert_eq!(d.decode(3.0), 3.0);
        assert_eq!(d.decode(4.0), 4.0);
        let d = SampleDecoder::new(ty("UInt16"), Some(65535.0), 1.0, 0.0);
        assert!(d.decode(65535.0).is_nan());
    }

    #[test]
    fn signed_byte_is_reinterpreted() {
        let t = SampleType::from_gdal("Byte", Some("SIGNEDBYTE")).expect("known");
        assert_eq!(t, SampleType::SignedByte);
        assert_eq!(t.display_name("Byte"), "Int8");
        let d = SampleDecoder::new(t, Some(-128.0), 1.0, 0.0);
        assert!(d.decode(128.0).is_nan());
        assert_eq!(d.decode(255.0), -1.0);
        assert_eq!(d.decode(127.0), 127.0);
    }

    #[test]
    fn scale_and_offset_apply_to_valid_samples_only() {
        let d = SampleDecoder::new(ty("UInt16"), Some(0.0), 0.1, -100.0);
        assert!(d.decode(0.0).is_nan());
        assert!((d.decode(1500.0) - 50.0).abs() < 1e-12);
    }

    #[test]
    fn complex_and_unknown_types_are_refused() {
        assert_eq!(SampleType::from_gdal("CFloat32", None), None);
        assert_eq!(SampleType::from_gdal("Unknown", None), None);
    }

    #[test]
    fn stats_track_counts_and_range() {
        let mut s = Stats::default();
        s.add(&[f64::NAN, f64::NAN]);
        assert_eq!((s.valid, s.nodata, s.min, s.max), (0, 2, None, None));
        s.add(&[3.0, f64::NAN, -1.0]);
        s.add(&[2.0]);
        assert_eq!(
            (s.valid, s.nodata, s.min, s.max),
            (3, 3, Some(-1.0), Some(3.0))
        );
    }
}
