//! Coordinate transformation between a raster's CRS and WGS84 longitude, latitude (GDAL's
//! PROJ), for writers that need RFC 7946 GeoJSON and for reading it back.

use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};

use crate::error::{Error, Result};

/// Points transformed per PROJ call.
const CHUNK: usize = 1 << 16;

/// A CRS from WKT (or anything GDAL's `SetFromUserInput` takes), in x = easting /
/// longitude, y = northing / latitude order.
fn spatial_ref(text: &str) -> Result<SpatialRef> {
    let mut srs = SpatialRef::from_definition(text).map_err(|source| Error::Crs {
        reason: format!("GDAL cannot read the CRS `{}`", short(text)),
        source: Box::new(source),
    })?;
    srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    Ok(srs)
}

/// The start of a long CRS text, for messages.
fn short(text: &str) -> String {
    let mut out: String = text.chars().take(60).collect();
    if out.len() < text.len() {
        out.push('…');
    }
    out
}

/// WGS84 (EPSG:4326) in longitude, latitude order.
fn wgs84() -> Result<SpatialRef> {
    spatial_ref("EPSG:4326")
}

/// Transforms `points` in place from `source` to `target`: x and y change, heights are
/// left as they are (no vertical transformation).
fn transform(source: &SpatialRef, target: &SpatialRef, points: &mut [[f64; 3]]) -> Result<()> {
    let transform = CoordTransform::new(source, target).map_err(|source| Error::Crs {
        reason: "PROJ has no transformation between the two CRSs".to_owned(),
        source: Box::new(source),
    })?;
    let mut xs = Vec::with_capacity(CHUNK.min(points.len()));
    let mut ys = Vec::with_capacity(CHUNK.min(points.len()));
    for (chunk_number, chunk) in points.chunks_mut(CHUNK).enumerate() {
        xs.clear();
        ys.clear();
        xs.extend(chunk.iter().map(|p| p[0]));
        ys.extend(chunk.iter().map(|p| p[1]));
        transform
            .transform_coords(&mut xs, &mut ys, &mut [])
            .map_err(|source| Error::Crs {
                reason: "PROJ failed to transform the coordinates".to_owned(),
                source: Box::new(source),
            })?;
        for (k, (p, (x, y))) in chunk.iter_mut().zip(xs.iter().zip(&ys)).enumerate() {
            if !(x.is_finite() && y.is_finite()) {
                return Err(Error::Untransformable {
                    point: chunk_number * CHUNK + k,
                    position: *p,
                });
            }
            p[0] = *x;
            p[1] = *y;
        }
    }
    Ok(())
}

/// Transforms `points` (x, y in the CRS given as WKT, heights) in place to WGS84
/// longitude, latitude in degrees (EPSG:4326 in traditional GIS order, as RFC 7946 GeoJSON
/// wants it). Heights are not changed.
///
/// # Errors
/// [`Error::Crs`] when GDAL cannot read the CRS or PROJ cannot transform between them,
/// [`Error::Untransformable`] for a point PROJ maps to no finite position. `points` may be
/// partly transformed after an error.
///
/// # Example
/// ```no_run
/// # fn main() -> Result<(), tinsmith_raster::Error> {
/// let mut points = [[1_200_000.0, 500_000.0, 812.5]];
/// tinsmith_raster::to_wgs84("EPSG:3005", &mut points)?;
/// assert!(points[0][0] < -114.0 && points[0][1] > 48.0);
/// # Ok(())
/// # }
/// ```
pub fn to_wgs84(source_wkt: &str, points: &mut [[f64; 3]]) -> Result<()> {
    transform(&spatial_ref(source_wkt)?, &wgs84()?, points)
}

/// The inverse of [`to_wgs84`]: WGS84 longitude, latitude to the CRS given as WKT, in
/// place; heights are not changed.
///
/// # Errors
/// As [`to_wgs84`].
pub fn from_wgs84(target_wkt: &str, points: &mut [[f64; 3]]) -> Result<()> {
    transform(&wgs84()?, &spatial_ref(target_wkt)?, points)
}

/// Whether `wkt` is WGS84 longitude, latitude in degrees, by its definition: a geographic
/// CRS on the WGS 84 datum (in any spelling: `WGS_1984`, `D_WGS_1984`, `World Geodetic
/// System 1984`, its ensemble; 2D or 3D), the Greenwich meridian and degrees. False for
/// anything else or anything GDAL cannot read (other datums are not WGS84, even where
/// PROJ has no transformation for a point and passes it through unchanged).
pub fn is_wgs84_lon_lat(wkt: &str) -> bool {
    let Ok(srs) = spatial_ref(wkt) else {
        return false;
    };
    if !srs.is_geographic() {
        return false;
    }
    let datum: String = srs
        .get_attr_value("DATUM", 0)
        .ok()
        .flatten()
        .unwrap_or_default()
        .chars()
        .filter(char::is_ascii_alphanumeric)
        .collect::<String>()
        .to_ascii_lowercase();
    let wgs84_datum = matches!(
        datum.trim_start_matches('d'),
        "wgs1984" | "wgs84" | "worldgeodeticsystem1984" | "worldgeodeticsystem1984ensemble"
    );
    let greenwich = srs
        .get_attr_value("PRIMEM", 1)
        .ok()
        .flatten()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .is_some_and(|v| v == 0.0);
    let degrees = (srs.angular_units() - std::f64::consts::PI / 180.0).abs() < 1e-12;
    wgs84_datum && greenwich && degrees
}

/// Whether the CRS given as WKT (or anything GDAL's `SetFromUserInput` takes) is
/// geographic: its x is a longitude in degrees.
///
/// # Errors
/// [`Error::Crs`] when GDAL cannot read the CRS.
pub fn is_geographic(wkt: &str) -> Result<bool> {
    Ok(spatial_ref(wkt)?.is_geographic())
}

/// The WKT of a CRS given as anything GDAL's `SetFromUserInput` takes (`EPSG:2193`, WKT,
/// PROJ strings).
///
/// # Errors
/// [`Error::Crs`] when GDAL cannot read the CRS.
pub fn crs_wkt(text: &str) -> Result<String> {
    let srs = spatial_ref(text)?;
    srs.to_wkt().map_err(|source| Error::Crs {
        reason: format!("GDAL cannot write the CRS `{}` as WKT", short(text)),
        source: Box::new(source),
    })
}

/// The EPSG code a CRS text names at its root (`ID["EPSG", ...]` in WKT2,
/// `AUTHORITY["EPSG", ...]` in WKT1, `EPSG:CODE`), if any: a CRS written from the EPSG
/// database by an older release keeps its code when its datum's name has changed since,
/// which GDAL's `IsSame` does not forgive.
pub fn epsg_code(text: &str) -> Option<u32> {
    let srs = spatial_ref(text).ok()?;
    if !srs.auth_name()?.eq_ignore_ascii_case("EPSG") {
        return None;
    }
    u32::try_from(srs.auth_code().ok()?).ok()
}

/// Whether two CRS texts (WKT in any dialect, ESRI's `.prj` included, or anything GDAL's
/// `SetFromUserInput` takes) name the same CRS, by GDAL's `IsSame` (axis order aside).
/// False when GDAL cannot read either.
pub fn same_crs(a: &str, b: &str) -> bool {
    match (spatial_ref(a), spatial_ref(b)) {
        (Ok(a), Ok(b)) => equivalent(&a, &b),
        _ => false,
    }
}

/// The horizontal part of a compound CRS given as WKT (its vertical CRS stripped, as
/// heights converted to another vertical reference must not claim it), as WKT; `wkt`
/// itself when it has no vertical part or GDAL cannot read it.
pub fn horizontal_crs(wkt: &str) -> String {
    let Ok(srs) = SpatialRef::from_wkt(wkt) else {
        return wkt.to_owned();
    };
    if !srs.is_compound() {
        return wkt.to_owned();
    }
    // SAFETY: the handle is live and owned by `srs`, which the call changes in place.
    #[allow(unsafe_code)]
    let stripped = unsafe { gdal_sys::OSRStripVertical(srs.to_c_hsrs()) };
    match stripped == gdal_sys::OGRErr::OGRERR_NONE {
        true => srs.to_wkt().unwrap_or_else(|_| wkt.to_owned()),
        false => wkt.to_owned(),
    }
}

/// GDAL's `IsSame` with the axis order of geographic CRSs and the data axis mapping aside:
/// ESRI's WGS84 (longitude, latitude axes) is EPSG:4326 (latitude, longitude), which plain
/// `IsSame` denies once both are read in the same x, y order.
pub(crate) fn equivalent(a: &SpatialRef, b: &SpatialRef) -> bool {
    let options = [
        c"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES".as_ptr(),
        c"CRITERION=EQUIVALENT_EXCEPT_AXIS_ORDER_GEOGCRS".as_ptr(),
        std::ptr::null(),
    ];
    // SAFETY: both handles are live; `options` is a NULL-terminated array of NUL-terminated
    // strings that outlive the call, which only reads them.
    #[allow(unsafe_code)]
    let same = unsafe { gdal_sys::OSRIsSameEx(a.to_c_hsrs(), b.to_c_hsrs(), options.as_ptr()) };
    same == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_crs_reads_through_spelling() {
        let utm = SpatialRef::from_epsg(32632).expect("EPSG:32632");
        let (wkt, pretty) = (
            utm.to_wkt().expect("WKT"),
            utm.to_pretty_wkt().expect("pretty WKT"),
        );
        assert!(same_crs(&wkt, "EPSG:32632"));
        assert!(same_crs(&wkt, &pretty));
        let esri_prj = "PROJCS[\"WGS_1984_UTM_Zone_32N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],PARAMETER[\"Central_Meridian\",9.0],PARAMETER[\"Scale_Factor\",0.9996],PARAMETER[\"Latitude_Of_Origin\",0.0],UNIT[\"Meter\",1.0]]";
        assert!(same_crs(&wkt, esri_prj));
        // ESRI's geographic WGS84 declares longitude, latitude axes; EPSG:4326 the reverse.
        let esri_wgs84 = "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",\
            6378137,298.257223563]],PRIMEM[\"Greenwich\",0],UNIT[\"Degree\",0.017453292519943295]]";
        assert!(same_crs("EPSG:4326", esri_wgs84));
        assert!(!same_crs("EPSG:4269", esri_wgs84));
        assert!(!same_crs(&wkt, "EPSG:32633"));
        assert!(!same_crs(&wkt, "not a CRS"));
    }

    #[test]
    fn wgs84_lon_lat_is_recognised_in_any_spelling() {
        let esri = "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]";
        for wkt in ["EPSG:4326", "EPSG:4979", "OGC:CRS84", esri] {
            assert!(is_wgs84_lon_lat(wkt), "{wkt}");
        }
        let ed50 = "GEOGCS[\"my ED50\",DATUM[\"European_Datum_1950\",SPHEROID[\"International 1924\",6378388,297]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]";
        let paris = "GEOGCS[\"WGS 84 Paris\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Paris\",2.33722917],UNIT[\"degree\",0.0174532925199433]]";
        for wkt in [
            "EPSG:32633",
            "EPSG:3857",
            "EPSG:4230",
            "EPSG:4267",
            ed50,
            paris,
            "not a CRS",
        ] {
            assert!(!is_wgs84_lon_lat(wkt), "{wkt}");
        }
    }

    #[test]
    fn utm_to_wgs84_and_back() -> Result<()> {
        // UTM 33N: the central meridian is 15 E; the false easting 500 000 is on it.
        let original = [[500_000.0, 0.0, 5.0], [500_000.0, 5_540_000.0, -3.25]];
        let mut points = original;
        to_wgs84("EPSG:32633", &mut points)?;
        assert!((points[0][0] - 15.0).abs() < 1e-9 && points[0][1].abs() < 1e-9);
        assert!((points[1][0] - 15.0).abs() < 1e-9 && (points[1][1] - 50.0).abs() < 0.1);
        assert_eq!([points[0][2], points[1][2]], [5.0, -3.25]);
        from_wgs84("EPSG:32633", &mut points)?;
        for (p, q) in points.iter().zip(&original) {
            assert!(
                (p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6,
                "{p:?}"
            );
        }
        Ok(())
    }

    #[test]
    fn geographic_or_not() -> Result<()> {
        assert!(is_geographic("EPSG:4326")?);
        assert!(is_geographic("EPSG:4269")?);
        assert!(!is_geographic("EPSG:32633")?);
        Ok(())
    }

    #[test]
    fn bad_crs_is_an_error() {
        let mut points = [[0.0; 3]];
        let error = to_wgs84("not a crs", &mut points).expect_err("bad CRS");
        assert!(error.to_string().contains("not a crs"), "{error}");
    }
}
