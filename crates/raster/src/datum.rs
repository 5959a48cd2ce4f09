//! Vertical datums: turning heights above a geoid (orthometric, as most DEMs hold them)
//! into heights above the WGS84 ellipsoid (what CesiumJS and RFC 7946 expect), through
//! PROJ's vertical grid shift.

use std::path::{Path, PathBuf};

use gdal::spatial_ref::{CoordTransform, CoordTransformOptions, SpatialRef};

use tinsmith_georef::GeoTransform;

use crate::error::{Error, Result};
use crate::info::RasterInfo;
use crate::read::OpenBand;

/// What the heights of a raster are measured from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum VerticalDatum {
    /// The WGS84 ellipsoid: heights are used as they are.
    Ellipsoid,
    /// The EGM96 geoid (EPSG:5773), from PROJ's `egm96_15.gtx` (Debian's `proj-data`).
    Egm96,
    /// The EGM2008 geoid (EPSG:3855), from PROJ's `us_nga_egm08_25.tif`, which is not in
    /// Debian's `proj-data`: download it from <https://cdn.proj.org/us_nga_egm08_25.tif>
    /// into a directory on PROJ's search path (`PROJ_DATA`, or `~/.local/share/proj`).
    Egm2008,
    /// A geoid model as a grid of its heights above the WGS84 ellipsoid, in any format
    /// PROJ's `vgridshift` reads (GTX, GeoTIFF): a national geoid such as GEOID18.
    Grid(PathBuf),
}

impl VerticalDatum {
    /// Parses `egm96`, `egm2008`, `ellipsoid` (any case), or else takes the text as a
    /// grid file's path (a name PROJ finds on its search path too).
    pub fn parse(text: &str) -> VerticalDatum {
        match text.to_ascii_lowercase().as_str() {
            "ellipsoid" | "wgs84" => VerticalDatum::Ellipsoid,
            "egm96" => VerticalDatum::Egm96,
            "egm2008" | "egm08" => VerticalDatum::Egm2008,
            _ => VerticalDatum::Grid(PathBuf::from(text)),
        }
    }

    /// A short name that identifies the datum whatever the machine: `ellipsoid`,
    /// `egm96`, `egm2008`, or `grid:` and the grid's file name.
    pub fn label(&self) -> String {
        match self {
            VerticalDatum::Ellipsoid => "ellipsoid".into(),
            VerticalDatum::Egm96 => "egm96".into(),
            VerticalDatum::Egm2008 => "egm2008".into(),
            VerticalDatum::Grid(path) => format!(
                "grid:{}",
                path.file_name().map_or_else(
                    || path.display().to_string(),
                    |n| n.to_string_lossy().into()
                )
            ),
        }
    }

    /// The text [`VerticalDatum::parse`] reads back as this datum.
    pub fn spec(&self) -> String {
        match self {
            VerticalDatum::Grid(path) => path.display().to_string(),
            other => other.label(),
        }
    }

    /// The grid PROJ shifts heights by; `None` for the ellipsoid.
    fn grid(&self) -> Option<String> {
        match self {
            VerticalDatum::Ellipsoid => None,
            VerticalDatum::Egm96 => Some("egm96_15.gtx".into()),
            VerticalDatum::Egm2008 => Some("us_nga_egm08_25.tif".into()),
            VerticalDatum::Grid(path) => Some(path.display().to_string()),
        }
    }
}

/// The vertical datum the raster at `path` declares in a compound CRS (its vertical
/// part): `Ok(None)` when it declares none.
///
/// # Errors
/// As [`crate::open_info`]; [`Error::VerticalDatum`] when the raster declares a vertical
/// CRS other than EGM96 or EGM2008 height (give its geoid grid instead).
pub fn declared_vertical_datum(path: &Path, band: usize) -> Result<Option<VerticalDatum>> {
    let opened = OpenBand::open(path, band)?;
    let Ok(srs) = opened.dataset().spatial_ref() else {
        return Ok(None);
    };
    if !srs.is_compound() {
        return Ok(None);
    }
    let wkt = srs.to_wkt().unwrap_or_default();
    let (name, code) = vertical_part(&wkt).unwrap_or_else(|| ("unnamed".into(), None));
    match code {
        Some(5773) => Ok(Some(VerticalDatum::Egm96)),
        Some(3855) => Ok(Some(VerticalDatum::Egm2008)),
        _ => Err(Error::VerticalDatum {
            path: path.to_path_buf(),
            reason: format!(
                "its heights are in the vertical CRS \"{name}\"{}, which tinsmith cannot turn \
                 into ellipsoidal heights by itself; give its geoid model as \
                 --vertical-datum GRIDFILE (or egm96, egm2008, ellipsoid)",
                code.map(|c| format!(" (EPSG:{c})")).unwrap_or_default()
            ),
        }),
    }
}

/// The name and EPSG code of the vertical part of a compound CRS's WKT 1
/// (`VERT_CS["name",...,AUTHORITY["EPSG","code"]]`: the code is the node's own, its last
/// child; its datum's comes before).
fn vertical_part(wkt: &str) -> Option<(String, Option<i32>)> {
    let start = wkt.find("VERT_CS[\"")? + "VERT_CS[\"".len();
    let name_end = wkt[start..].find('"')?;
    let name = wkt[start..start + name_end].to_owned();
    let mut depth = 1;
    let mut end = wkt.len();
    for (k, c) in wkt[start..].char_indices() {
        match c {
            '[' => depth += 1,
            ']' => {
                depth -= 1;
                if depth == 0 {
                    end = start + k;
                    break;
                }
            }
            _ => {}
        }
    }
    let node = &wkt[start..end];
    let code = node.rfind("AUTHORITY[\"EPSG\",\"").and_then(|at| {
        let digits = &node[at + "AUTHORITY[\"EPSG\",\"".len()..];
        digits[..digits.find('"')?].parse().ok()
    });
    Some((name, code))
}

/// Heights of a geoid above the WGS84 ellipsoid at longitude, latitude points, as PROJ's
/// `vgridshift` interpolates its grid: `h = H + N`.
pub struct Geoid {
    datum: VerticalDatum,
    transform: CoordTransform,
}

impl std::fmt::Debug for Geoid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Geoid").field("datum", &self.datum).finish()
    }
}

impl Geoid {
    /// The geoid of `datum`; `Ok(None)` for the ellipsoid.
    ///
    /// # Errors
    /// [`Error::VerticalDatum`] naming the grid when PROJ cannot find or read it (it
    /// never falls back to a shift of zero, as PROJ's "ballpark" transformations would).
    pub fn new(datum: &VerticalDatum) -> Result<Option<Geoid>> {
        let Some(grid) = datum.grid() else {
            return Ok(None);
        };
        let pipeline = format!(
            "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad \
             +step +proj=vgridshift +grids={grid} +multiplier=1 \
             +step +proj=unitconvert +xy_in=rad +xy_out=deg"
        );
        let unavailable = |reason: String| Error::VerticalDatum {
            path: PathBuf::from(&grid),
            reason,
        };
        let mut options = CoordTransformOptions::new().map_err(|e| unavailable(e.to_string()))?;
        options
            .set_coordinate_operation(&pipeline, false)
            .map_err(|e| unavailable(e.to_string()))?;
        // Longitude first in the CRS's own axis order, so that GDAL hands PROJ's pipeline
        // the coordinates as given (with EPSG:4326 it would swap them first).
        let lon_lat = SpatialRef::from_proj4("+proj=longlat +datum=WGS84 +no_defs")
            .map_err(|e| unavailable(e.to_string()))?;
        let transform =
            CoordTransform::new_with_options(&lon_lat, &lon_lat, &options).map_err(|e| {
                unavailable(format!(
                    "PROJ cannot use this geoid grid ({e}); {}",
                    where_grids_go(datum)
                ))
            })?;
        let geoid = Geoid {
            datum: datum.clone(),
            transform,
        };
        // PROJ opens grids lazily: a grid it cannot find fails on the first point.
        geoid.undulations(&[0.0], &[0.0]).map_err(|e| match e {
            Error::VerticalDatum { reason, .. } => unavailable(reason),
            e => e,
        })?;
        Ok(Some(geoid))
    }

    /// The datum this geoid is of.
    pub fn datum(&self) -> &VerticalDatum {
        &self.datum
    }

    /// The geoid's height above the ellipsoid `N` at each (`lon`, `lat`) in degrees.
    ///
    /// # Errors
    /// [`Error::VerticalDatum`] when a point is outside the grid (a regional geoid) or
    /// PROJ fails.
    pub fn undulations(&self, lon: &[f64], lat: &[f64]) -> Result<Vec<f64>> {
        let mut x = lon.to_vec();
        let mut y = lat.to_vec();
        let mut z = vec![0.0; lon.len()];
        if lon.is_empty() {
            return Ok(z);
        }
        let grid = self.datum.grid().unwrap_or_default();
        self.transform
            .transform_coords(&mut x, &mut y, &mut z)
            .map_err(|e| Error::VerticalDatum {
                path: PathBuf::from(&grid),
                reason: format!(
                    "PROJ cannot shift heights by this geoid grid at one of {} points \
                     (from {:.4}, {:.4}): {e}; {}",
                    lon.len(),
                    lon[0],
                    lat[0],
                    where_grids_go(&self.datum)
                ),
            })?;
        if let Some(k) = z.iter().position(|v| !v.is_finite()) {
            return Err(Error::VerticalDatum {
                path: PathBuf::from(&grid),
                reason: format!(
                    "the geoid grid does not cover longitude {:.4}, latitude {:.4}",
                    lon[k], lat[k]
                ),
            });
        }
        Ok(z)
    }
}

/// A raster's heights above a geoid turned into heights above the WGS84 ellipsoid at its
/// samples: each valid sample gains the geoid's height `N` at the sample's centre (its
/// position in the raster's CRS taken to WGS84 longitude, latitude by PROJ, then `N` as
/// [`Geoid::undulations`] interpolates it). The same sample always gains the same `N`,
/// whichever window or strip it is read in.
///
/// It holds no PROJ object (a reader that holds one must stay `Send`): each
/// [`HeightShift::apply`] sets up its own transformations, a small cost beside a window's
/// samples.
pub(crate) struct HeightShift {
    datum: VerticalDatum,
    crs_wkt: String,
    transform: GeoTransform,
}

impl HeightShift {
    /// The shift of `datum`'s heights for the raster `info` describes; `Ok(None)` for the
    /// ellipsoid (heights used as they are).
    ///
    /// # Errors
    /// [`Error::VerticalDatum`] naming the raster when it has no CRS or no geotransform
    /// (the geoid cannot be placed), or as [`Geoid::new`].
    pub(crate) fn new(info: &RasterInfo, datum: &VerticalDatum) -> Result<Option<HeightShift>> {
        // Checked now, so that a missing grid fails before any sample is read.
        if Geoid::new(datum)?.is_none() {
            return Ok(None);
        }
        let (Some(crs_wkt), Some(transform)) = (info.crs_wkt.clone(), info.transform()) else {
            return Err(Error::VerticalDatum {
                path: info.path.clone(),
                reason: format!(
                    "heights above {} need the raster's position on the globe, and it has no \
                     CRS or no geotransform",
                    datum.label()
                ),
            });
        };
        Ok(Some(HeightShift {
            datum: datum.clone(),
            crs_wkt,
            transform,
        }))
    }

    /// Adds `N` to every finite sample of the `size.0` x `size.1` window (row-major
    /// `values`) whose top-left sample is `origin`.
    ///
    /// # Errors
    /// [`Error::Crs`] when PROJ cannot take a sample to WGS84; [`Error::VerticalDatum`]
    /// when the geoid grid does not cover one.
    pub(crate) fn apply(
        &self,
        origin: (usize, usize),
        size: (usize, usize),
        values: &mut [f64],
    ) -> Result<()> {
        let valid: Vec<usize> = (0..values.len())
            .filter(|&i| values[i].is_finite())
            .collect();
        if valid.is_empty() {
            return Ok(());
        }
        let mut points: Vec<[f64; 3]> = valid
            .iter()
            .map(|&i| {
                let (x, y) = (origin.0 + i % size.0, origin.1 + i / size.0);
                let [px, py] = self.transform.sample_centre(x as f64, y as f64);
                [px, py, 0.0]
            })
            .collect();
        crate::reproject::to_wgs84(&self.crs_wkt, &mut points)?;
        let lon: Vec<f64> = points.iter().map(|p| p[0]).collect();
        let lat: Vec<f64> = points.iter().map(|p| p[1]).collect();
        let geoid = Geoid::new(&self.datum)?.expect("a geoid, as `new` found");
        let n = geoid.undulations(&lon, &lat)?;
        for (&i, n) in valid.iter().zip(n) {
            values[i] += n;
        }
        Ok(())
    }
}

/// How to give PROJ the grid of `datum`.
fn where_grids_go(datum: &VerticalDatum) -> String {
    match datum {
        VerticalDatum::Egm96 => "install Debian's proj-data, which has egm96_15.gtx".into(),
        VerticalDatum::Egm2008 => "download https://cdn.proj.org/us_nga_egm08_25.tif into \
             ~/.local/share/proj (or a directory named by PROJ_DATA)"
            .into(),
        _ => "give the grid's path, or put it in ~/.local/share/proj (or PROJ_DATA)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertical_part_of_a_compound_crs_is_found() {
        let srs = SpatialRef::from_definition("EPSG:4326+5773").unwrap();
        assert!(srs.is_compound());
        let (name, code) = vertical_part(&srs.to_wkt().unwrap()).unwrap();
        assert_eq!((name.as_str(), code), ("EGM96 height", Some(5773)));
        let srs = SpatialRef::from_definition("EPSG:32633+5703").unwrap();
        let (name, code) = vertical_part(&srs.to_wkt().unwrap()).unwrap();
        assert_eq!((name.as_str(), code), ("NAVD88 height", Some(5703)));
        assert!(vertical_part(&SpatialRef::from_epsg(4326).unwrap().to_wkt().unwrap()).is_none());
    }

    #[test]
    fn names_parse_and_label() {
        assert_eq!(VerticalDatum::parse("EGM96"), VerticalDatum::Egm96);
        assert_eq!(VerticalDatum::parse("egm2008"), VerticalDatum::Egm2008);
        assert_eq!(VerticalDatum::parse("ellipsoid"), VerticalDatum::Ellipsoid);
        let grid = VerticalDatum::parse("/grids/g2018u0.tif");
        assert_eq!(grid.label(), "grid:g2018u0.tif");
        assert_eq!(VerticalDatum::Egm96.label(), "egm96");
    }

    #[test]
    fn egm96_at_fuji_is_what_proj_gives_and_a_missing_grid_is_an_error() {
        let geoid = Geoid::new(&VerticalDatum::Egm96)
            .expect("proj-data's egm96_15.gtx")
            .expect("a geoid");
        let n = geoid.undulations(&[138.73, 0.0], &[35.36, 0.0]).unwrap();
        // `echo "138.73 35.36 0" | gdaltransform -s_srs EPSG:4326+5773 -t_srs EPSG:4979`
        assert!((n[0] - 41.2414757629395).abs() < 1e-6, "{n:?}");
        assert!(n[1].abs() < 100.0 && n[1] != 0.0);
        assert!(Geoid::new(&VerticalDatum::Ellipsoid).unwrap().is_none());
        let missing = VerticalDatum::Grid(PathBuf::from("/nonexistent/geoid.gtx"));
        let err = Geoid::new(&missing).unwrap_err().to_string();
        assert!(err.contains("/nonexistent/geoid.gtx"), "{err}");
    }
}
