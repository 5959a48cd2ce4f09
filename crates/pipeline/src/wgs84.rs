//! Positions for RFC 7946 GeoJSON: reprojection to WGS84 longitude, latitude, for `mesh`
//! and `contour` alike ([`file_crs`]), and the checks that a mesh reprojected so can be
//! read back (no pole inside, no fold, every vertex back on its sample).

use std::path::Path;

use tinsmith_formats::CrsRef;
use tinsmith_raster::RasterInfo;

use crate::error::{bail, Context};
use crate::Feedback;
use crate::Result;

/// The CRS a file written from `raster` records: none with `--pixel-coords` or without a
/// geotransform, else the raster's. With `wgs84` (GeoJSON without `--geojson-source-crs`,
/// for `mesh` and `contour` alike) a raster with a CRS has `points` (file coordinates)
/// reprojected in place to WGS84 longitude, latitude (RFC 7946), heights unchanged, and
/// the file records EPSG 4326; without a CRS the points stay as they are, with a note.
pub fn file_crs<'r>(
    info: &'r RasterInfo,
    pixel_coords: bool,
    wgs84: bool,
    points: &mut [[f64; 3]],
    pieces: Pieces<'_>,
    path: &Path,
    feedback: &dyn Feedback,
) -> Result<CrsRef<'r>> {
    let crs = match pixel_coords || info.transform().is_none() {
        true => CrsRef::default(),
        false => CrsRef::new(info.crs_wkt.as_deref(), info.epsg),
    };
    if !wgs84 {
        return Ok(crs);
    }
    match crs.wkt {
        Some(wkt) => {
            tinsmith_raster::to_wgs84(wkt, points)
                .with_context(|| format!("{}: cannot reproject to WGS84", path.display()))?;
            if !tinsmith_raster::is_geographic(wkt)? {
                let pole = pole_inside(info, wkt);
                match (pole, pieces) {
                    (None, _) => unwrap_around_centre(info, wkt, points).with_context(|| {
                        format!("{}: cannot reproject to WGS84", path.display())
                    })?,
                    (Some(pole), Pieces::Mesh) => {
                        bail!("{}: {}", path.display(), pole_message(pole))
                    }
                    (Some(_), Pieces::Lines(ends)) => unwrap_along_lines(points, ends),
                }
            }
            if let Some(p) = points.iter().find(|p| p[1].abs() > 90.0 + 1e-9) {
                bail!(
                    "{}: the raster reaches latitude {}, beyond the pole (is its \
                     georeferencing right?): RFC 7946 GeoJSON cannot hold it; write to .fgb \
                     or another format",
                    path.display(),
                    p[1]
                );
            }
            Ok(CrsRef::new(None, Some(4326)))
        }
        None => {
            feedback.note(&format!(
                "{}: no CRS, so the coordinates are written as they are, with \"crs\": null",
                path.display()
            ));
            Ok(crs)
        }
    }
}

/// What the points given to [`file_crs`] are.
#[derive(Debug, Clone, Copy)]
pub enum Pieces<'a> {
    /// A mesh's vertices (shared by triangles).
    Mesh,
    /// Lines, one after the other (see [`LineEnd`]).
    Lines(&'a [LineEnd]),
}

/// A line's end (one past its last point) in a shared point buffer, its level, and whether
/// it is a closed ring.
pub type LineEnd = (usize, f64, bool);

/// Which pole ("north" or "south") lies within the hull of a projected raster's sample
/// centres, if any: its longitudes then go all the way round.
fn pole_inside(info: &RasterInfo, wkt: &str) -> Option<&'static str> {
    let transform = info.transform()?;
    [(90.0, "north"), (-90.0, "south")]
        .into_iter()
        .find(|&(lat, _)| {
            let mut pole = [[0.0, lat, 0.0]];
            tinsmith_raster::from_wgs84(wkt, &mut pole).is_ok()
                && pole[0].iter().all(|v| v.is_finite())
                && transform
                    .world_to_sample([pole[0][0], pole[0][1]])
                    .is_some_and(|[x, y]| {
                        (-0.5..=f64::from(info.width) - 0.5).contains(&x)
                            && (-0.5..=f64::from(info.height) - 0.5).contains(&y)
                    })
        })
        .map(|(_, name)| name)
}

/// Around a pole no frame of longitudes is continuous over the whole raster, but along a
/// line each step is short: each point's longitude is moved by whole turns to within 180°
/// of the point before it (the GeoJSON writer then cuts at the antimeridian).
fn unwrap_along_lines(points: &mut [[f64; 3]], ends: &[LineEnd]) {
    let mut start = 0;
    for &(end, _, _) in ends {
        for i in start + 1..end {
            let previous = points[i - 1][0];
            let p = &mut points[i][0];
            *p = previous + (*p - previous + 180.0).rem_euclid(360.0) - 180.0;
        }
        start = end;
    }
}

/// PROJ gives a projected raster's longitudes in [-180, 180], so one that spans the
/// antimeridian jumps there; the GeoJSON writers want one continuous frame (they cut at
/// 180 themselves, RFC 7946), so longitudes are moved by a turn where they lie more than
/// 180° from the raster centre's.
fn unwrap_around_centre(info: &RasterInfo, wkt: &str, points: &mut [[f64; 3]]) -> Result<()> {
    let Some(transform) = info.transform() else {
        return Ok(());
    };
    let [x, y] = transform.sample_centre(
        f64::from(info.width) / 2.0 - 0.5,
        f64::from(info.height) / 2.0 - 0.5,
    );
    let mut centre = [[x, y, 0.0]];
    tinsmith_raster::to_wgs84(wkt, &mut centre)?;
    let c = centre[0][0];
    for p in points {
        if p[0] - c > 180.0 {
            p[0] -= 360.0;
        } else if p[0] - c < -180.0 {
            p[0] += 360.0;
        }
    }
    Ok(())
}

/// Longitudes within 1e-9° of the antimeridian (180 + 360 j) put on it, for GeoJSON in
/// EPSG:4326 (reprojected, or the raster's own with `--geojson-source-crs`): a 0..360
/// grid's "180" column computed through its geotransform can lie at 179.9999999999998,
/// and the GeoJSON writers would cut the triangles and lines beside it into slivers 1e-13°
/// wide. (1e-9° is 0.1 mm, far below any raster's spacing; the longitudes it moves are
/// off the meridian by rounding alone, about 1e-13°, well within what the verifier
/// allows.)
pub fn snap_to_antimeridian(points: &mut [[f64; 3]]) {
    for p in points {
        let meridian = 180.0 + 360.0 * ((p[0] - 180.0) / 360.0).round();
        if (p[0] - meridian).abs() < 1e-9 {
            p[0] = meridian;
        }
    }
}

/// Fails early when a mesh of the raster cannot be written as RFC 7946 GeoJSON: a pole in
/// a projected raster (see [`file_crs`]), or a corner sample that does not come back from
/// WGS84 (see [`check_wgs84_maps_back`]; `write` checks every vertex again).
pub fn check_wgs84_mesh_possible(info: &RasterInfo, path: &Path) -> Result<()> {
    let Some((wkt, transform)) = projected_crs(info)? else {
        return Ok(());
    };
    if let Some(pole) = pole_inside(info, wkt) {
        bail!("{}: {}", path.display(), pole_message(pole));
    }
    let (w, h) = (f64::from(info.width) - 1.0, f64::from(info.height) - 1.0);
    let world: Vec<[f64; 3]> = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h), (w / 2.0, h / 2.0)]
        .into_iter()
        .map(|(x, y)| {
            let [x, y] = transform.sample_centre(x, y);
            [x, y, 0.0]
        })
        .collect();
    let mut lon_lat = world.clone();
    tinsmith_raster::to_wgs84(wkt, &mut lon_lat)
        .with_context(|| format!("{}: cannot reproject to WGS84", path.display()))?;
    check_wgs84_maps_back(&world, &lon_lat, (wkt, transform), path)
}

/// The raster's CRS (WKT) and geotransform when it is georeferenced in a projected CRS
/// (not EPSG:4326 or another geographic one): whose positions WGS84 GeoJSON reprojects.
pub fn projected_crs(info: &RasterInfo) -> Result<Option<(&str, tinsmith_georef::GeoTransform)>> {
    let (Some(wkt), Some(transform)) = (info.crs_wkt.as_deref(), info.transform()) else {
        return Ok(None);
    };
    Ok((!is_geographic(info, wkt)?).then_some((wkt, transform)))
}

/// Whether the raster's CRS, `wkt`, is EPSG:4326 or another geographic one.
pub fn is_geographic(info: &RasterInfo, wkt: &str) -> Result<bool> {
    Ok(info.epsg == Some(4326) || tinsmith_raster::is_geographic(wkt)?)
}

fn pole_message(pole: &str) -> String {
    format!(
        "the raster contains the {pole} pole, around which WGS84 longitudes wrap: RFC 7946 \
         GeoJSON cannot hold the triangles there; write with --geojson-source-crs (the \
         raster's CRS) or to .fgb"
    )
}

/// The last gate for WGS84 GeoJSON from a projected raster (its CRS and geotransform):
/// every vertex's longitude and latitude transform back to the sample it came from
/// (`world`, in the raster's CRS), as
/// `tinsmith verify` will transform them. A raster reaching past its CRS's valid area (Web
/// Mercator x beyond the antimeridian) would come back elsewhere.
pub fn check_wgs84_maps_back(
    world: &[[f64; 3]],
    lon_lat: &[[f64; 3]],
    (wkt, transform): (&str, tinsmith_georef::GeoTransform),
    path: &Path,
) -> Result<()> {
    let mut back = lon_lat.to_vec();
    tinsmith_raster::from_wgs84(wkt, &mut back)
        .with_context(|| format!("{}: cannot transform WGS84 back", path.display()))?;
    for (w, b) in world.iter().zip(&back) {
        let sample = |p: &[f64; 3]| transform.world_to_sample([p[0], p[1]]);
        let (Some(s), Some(t)) = (sample(w), sample(b)) else {
            continue;
        };
        if !((s[0] - t[0]).abs() <= 1e-3 && (s[1] - t[1]).abs() <= 1e-3) {
            bail!(
                "{}: the vertex at ({}, {}) comes back from WGS84 at ({}, {}): the raster \
                 reaches beyond its CRS's valid area, so RFC 7946 GeoJSON could not be read \
                 back; write with --geojson-source-crs (the raster's CRS) or to .fgb",
                path.display(),
                w[0],
                w[1],
                b[0],
                b[1]
            );
        }
    }
    Ok(())
}

/// The sine of the angle below which a triangle turned over in longitude/latitude is a
/// sliver bent by the projection's curvature, not a fold (see [`check_no_fold_in_lon_lat`]).
const FOLD_MIN_SINE: f64 = 0.05;

/// Fails when some triangle, reprojected to longitude, latitude, is clearly wound against
/// the others: near a pole a straight edge of the raster's CRS can pass around it, and the
/// triangle then folds over its neighbours in the plane RFC 7946 GeoJSON is read in (found
/// on polar stereographic rasters whose extent stops short of the pole).
///
/// Slivers are not counted: anywhere, straight lines of a projected CRS curve a little in
/// longitude/latitude, enough to turn over a triangle thinner than that curvature (a
/// decimated 72 km x 112 m triangle over flat sea at 66 N), which overlaps its neighbours
/// only by its own width. A triangle counts when the sine of its angle at its first corner
/// (twice its area over the product of the two sides there, which for a thin triangle is
/// about its height over its length), measured with longitude differences scaled by the
/// cosine of the triangle's mean latitude (so that near a pole a degree of longitude is
/// not taken for a degree of latitude), is above [`FOLD_MIN_SINE`].
pub fn check_no_fold_in_lon_lat(
    lon_lat: &[[f64; 3]],
    triangles: &[[u32; 3]],
    path: &Path,
) -> Result<()> {
    let signed = |t: &[u32; 3]| -> f64 {
        let [a, b, c] = t.map(|v| lon_lat[v as usize]);
        let k = ((a[1] + b[1] + c[1]) / 3.0).to_radians().cos();
        let (u, w) = (
            [(b[0] - a[0]) * k, b[1] - a[1]],
            [(c[0] - a[0]) * k, c[1] - a[1]],
        );
        let cross = u[0] * w[1] - u[1] * w[0];
        let scale = u[0].hypot(u[1]) * w[0].hypot(w[1]);
        if cross.abs() > FOLD_MIN_SINE * scale {
            cross.signum()
        } else {
            0.0
        }
    };
    let (positive, negative) =
        triangles
            .iter()
            .fold((0usize, 0usize), |(p, n), t| match signed(t) {
                s if s > 0.0 => (p + 1, n),
                s if s < 0.0 => (p, n + 1),
                _ => (p, n),
            });
    let folded = positive.min(negative);
    if folded > 0 {
        bail!(
            "{}: {folded} of {} triangles fold over their neighbours in longitude/latitude \
             (straight edges of the raster's CRS curve in longitude/latitude, most near a \
             pole or far from the projection's centre), so RFC 7946 GeoJSON cannot hold \
             the mesh; write with --geojson-source-crs (the raster's CRS) or to .fgb, or \
             keep triangles small with --max-edge-length",
            path.display(),
            triangles.len()
        );
    }
    Ok(())
}
