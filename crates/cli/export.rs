//! How `tinsmith mesh` writes each format: the format and its flags, the float32 origin
//! and the tighter bound that keeps the promise in float32 files; WGS84 for GeoJSON, for
//! `mesh` and `contour` alike ([`file_crs`]).

use std::path::Path;

use anyhow::{bail, Context, Result};
use serde::Serialize;
use tinsmith_core::Grid;
use tinsmith_export::{CrsRef, LocalOrigin, MeshFormat, MeshRef, WriteOptions};
use tinsmith_raster::RasterInfo;

use crate::args::MeshArgs;
use crate::georef::Georef;
use crate::number::readable;
use crate::output::NamingFile;

/// Largest rounding of a float32 position, in pixels, accepted before decimating: 90 % of
/// the 1e-3 pixel within which the verifier maps file positions to samples. Half a float32
/// step is 2^-24 of the offset, so rasters up to about 30,000 samples across pass.
const MAX_POSITION_ROUNDING_PX: f64 = 9e-4;

/// The format `mesh` writes: `--format` or the extension; fails when a format-specific
/// flag is given for another format.
pub fn format(args: &MeshArgs) -> Result<MeshFormat> {
    let format = match args.export.format {
        Some(format) => format,
        None => MeshFormat::from_path(out(args))?,
    };
    let e = &args.export;
    let misplaced = [
        (e.base.is_some(), "--base", MeshFormat::Stl),
        (e.normals, "--normals", MeshFormat::Glb),
        (
            e.geojson_source_crs,
            "--geojson-source-crs",
            MeshFormat::GeoJson,
        ),
    ];
    for (given, flag, only) in misplaced {
        if given && format != only {
            bail!(
                "{}: {flag} applies to {only} output only, not {format}",
                out(args).display()
            );
        }
    }
    if let Some(base) = e.base {
        if !base.is_finite() {
            bail!("--base must be a finite number, got {base}");
        }
    }
    Ok(format)
}

/// What the output format needs decided before decimation.
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    pub format: MeshFormat,
    /// The float32 formats' origin.
    pub origin: Option<LocalOrigin>,
    /// max |z - stored z| over every valid sample (0 for `f64` formats).
    pub height_rounding: f64,
    /// The bound given to the decimator: `--max-error` less `height_rounding`, so that
    /// the heights as stored are within `--max-error` of every sample.
    pub decimation_bound: f64,
}

/// The float32 part of the `--report` JSON.
#[derive(Debug, Serialize)]
pub struct PlanReport {
    format: &'static str,
    local_origin: Option<[f64; 3]>,
    float32_height_rounding: f64,
    decimation_max_error: f64,
}

impl Plan {
    /// Notes on stderr the float32 formats' origin and height rounding for `output`
    /// (nothing for the double-precision formats).
    pub fn note_origin(&self, output: &Path) {
        if let Some(origin) = self.origin {
            let [x, y, z] = origin.offset();
            note!(
                "{}: float32 positions relative to the local origin ({x}, {y}, {z}); \
                 heights round by at most {}",
                output.display(),
                self.height_rounding
            );
        }
    }

    /// For STL and glTF: the origin in the middle of the raster's file coordinates and
    /// heights, the largest float32 rounding of a height, and the bound left for the
    /// decimator; fails when float32 cannot hold the positions to a sample or the heights
    /// within `max_error`. With the `grid` in memory and vertices at their samples the
    /// rounding is measured at every valid sample; otherwise (the tiled engine, raised
    /// vertex heights) it is bounded from the height range.
    pub fn new(
        format: MeshFormat,
        info: &RasterInfo,
        grid: Option<&Grid>,
        args: &MeshArgs,
    ) -> Result<Plan> {
        let max_error = args.max_error.unwrap_or(f64::INFINITY);
        if format == MeshFormat::GeoJson && !args.export.geojson_source_crs && !args.pixel_coords {
            // Before any work: what `write` would refuse for the raster as a whole.
            check_wgs84_mesh_possible(info, out(args))?;
        }
        // Decimation refuses such heights, whatever the format: say that, not that float32
        // rounds them beyond the bound.
        if let Some(max_abs) = info
            .max_abs_value()
            .filter(|&v| v > tinsmith_core::MAX_ABS_HEIGHT)
        {
            return Err(tinsmith_core::Error::HeightsTooLarge(max_abs)).naming_file(&args.input);
        }
        if !format.is_float32() {
            return Ok(Plan {
                format,
                origin: None,
                height_rounding: 0.0,
                decimation_bound: max_error,
            });
        }
        if let (Some(base), Some(min)) = (args.export.base, info.min) {
            if base >= min {
                bail!(
                    "{}: --base {base} must be below the lowest height ({min})",
                    out(args).display()
                );
            }
        }
        let georef = Georef::new(info.transform(), args.pixel_coords);
        note_degrees_in_a_3d_format(info, &georef, args)?;
        let (min, max) = extent(info, &georef);
        let origin = LocalOrigin::around(min, max);
        if let Some(base) = args.export.base {
            // The solid's floor is written as float32 like every other coordinate.
            if !((base - origin.offset()[2]) as f32).is_finite() {
                bail!(
                    "{}: --base {base} is beyond the range of the format's float32 coordinates",
                    out(args).display()
                );
            }
        }
        check_position_rounding(info, &georef, origin, min, max, out(args))?;

        // Raised vertex heights are not samples: bound their rounding from the range, up
        // to the highest sample raised (by at most the raise for the whole bound; the
        // decimation's bound is smaller).
        let samples_only = !args.raises_vertex_heights(info.min.zip(info.max));
        let raise = if samples_only {
            0.0
        } else {
            tinsmith_core::vertex_raise(max_error, info.max_abs_value().unwrap_or(0.0))
        };
        let height_rounding = match grid.filter(|_| samples_only) {
            Some(grid) => {
                let mut rounding = 0.0f64;
                for &z in grid.values().iter().filter(|z| z.is_finite()) {
                    let stored = origin.quantize([0.0, 0.0, z])[2];
                    rounding = rounding.max((stored - z).abs());
                }
                rounding
            }
            None => height_rounding_bound(origin, min[2], max[2] + raise),
        };
        let decimation_bound = max_error - height_rounding;
        if decimation_bound < 0.0 {
            bail!(
                "{}: --max-error {} is smaller than the float32 rounding of the heights ({}) \
                 in {format}; use a larger bound or a double-precision format (.ply, .obj, \
                 .fgb, .geojson, .xml)",
                out(args).display(),
                readable(max_error),
                readable(height_rounding)
            );
        }
        Ok(Plan {
            format,
            origin: Some(origin),
            height_rounding,
            decimation_bound,
        })
    }

    /// The height the file will give back for `z`.
    pub fn file_height(&self, z: f64) -> f64 {
        match self.origin {
            Some(origin) => origin.quantize([0.0, 0.0, z])[2],
            None => z,
        }
    }

    /// What goes into the `--report` JSON.
    pub fn report(&self) -> PlanReport {
        PlanReport {
            format: self.format.name(),
            local_origin: self.origin.map(|o| o.offset()),
            float32_height_rounding: self.height_rounding,
            decimation_max_error: self.decimation_bound,
        }
    }
}

/// An upper bound on |stored - z| for every height `z` in `[min, max]` stored as float32
/// relative to `origin`: half a float32 step of the largest offset (2^-24 of it), plus the
/// `f64` roundings of the subtraction and the addition back, with a factor 2 to spare.
fn height_rounding_bound(origin: LocalOrigin, min: f64, max: f64) -> f64 {
    let oz = origin.offset()[2];
    let offset = (max - oz).abs().max((min - oz).abs());
    let magnitude = max.abs().max(min.abs());
    2.0 * (offset * 2f64.powi(-24) + (offset + magnitude) * 2f64.powi(-52))
}

/// For STL and glTF, before reading any sample: fails when the raster is too wide for
/// float32 positions (see [`Plan::new`]; the positions depend only on the size and the
/// geotransform, so a huge raster is refused before its statistics scan).
pub fn check_float32_positions(
    format: MeshFormat,
    info: &RasterInfo,
    args: &MeshArgs,
) -> Result<()> {
    if !format.is_float32() {
        return Ok(());
    }
    let georef = Georef::new(info.transform(), args.pixel_coords);
    let (min, max) = extent(info, &georef);
    let origin = LocalOrigin::around(min, max);
    check_position_rounding(info, &georef, origin, min, max, out(args))
}

/// Min and max of the raster's file coordinates (sample centres) and valid heights.
fn extent(info: &RasterInfo, georef: &Georef) -> ([f64; 3], [f64; 3]) {
    let (w, h) = (info.width.saturating_sub(1), info.height.saturating_sub(1));
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for (x, y) in [(0, 0), (w, 0), (0, h), (w, h)] {
        let p = georef.file_position(x, y);
        for axis in 0..2 {
            min[axis] = min[axis].min(p[axis]);
            max[axis] = max[axis].max(p[axis]);
        }
    }
    // The statistics of the heights decimation sees (after scale and offset).
    min[2] = info.min.unwrap_or(0.0);
    max[2] = info.max.unwrap_or(0.0);
    (min, max)
}

/// Fails when float32 offsets from `origin` cannot place every sample within
/// [`MAX_POSITION_ROUNDING_PX`] of its centre (a bound: half a float32 step at the largest
/// offset, plus the `f64` roundings, in pixels through the inverse geotransform).
fn check_position_rounding(
    info: &RasterInfo,
    georef: &Georef,
    origin: LocalOrigin,
    min: [f64; 3],
    max: [f64; 3],
    output: &Path,
) -> Result<()> {
    let o = origin.offset();
    let mut world = 0.0f64;
    for axis in 0..2 {
        let offset = (max[axis] - o[axis]).abs().max((min[axis] - o[axis]).abs());
        let magnitude = max[axis].abs().max(min[axis].abs());
        world = world.max(offset * 2f64.powi(-24) + magnitude * 2f64.powi(-51));
    }
    // Pixels per world unit: the inverse geotransform's largest row sum.
    let per_unit = match georef {
        Georef::Pixel => 1.0,
        Georef::World(t) => {
            let c = &t.0;
            let det = (c[1] * c[5] - c[2] * c[4]).abs();
            ((c[5].abs() + c[2].abs()).max(c[4].abs() + c[1].abs())) / det
        }
    };
    let pixels = world * per_unit;
    if !pixels.is_finite() || pixels > MAX_POSITION_ROUNDING_PX {
        bail!(
            "{}: a {}x{} raster is too large for float32 positions relative to one origin \
             (rounding up to {pixels:.2e} pixel); use a double-precision format (.ply, \
             .obj, .fgb, .geojson, .xml)",
            output.display(),
            info.width,
            info.height
        );
    }
    Ok(())
}

/// Writes the mesh (`vertices` in file coordinates, counter-clockwise `triangles`) as the
/// plan's format with the raster's CRS: reprojected to WGS84 for GeoJSON unless
/// `--geojson-source-crs`; a `.prj` sidecar for OBJ, STL and glTF.
pub fn write(
    plan: &Plan,
    args: &MeshArgs,
    info: &RasterInfo,
    mut vertices: Vec<[f64; 3]>,
    triangles: &[[u32; 3]],
) -> Result<()> {
    let path = out(args);
    if plan.format == MeshFormat::FlatGeobuf {
        check_flatgeobuf_fits(path, triangles.len())?;
    }
    let wgs84 = plan.format == MeshFormat::GeoJson && !args.export.geojson_source_crs;
    // A projected raster's positions, to check they come back from WGS84.
    let projected = match wgs84 {
        true => projected_crs(info)?,
        false => None,
    };
    let world = projected.map(|_| vertices.clone());
    let crs = file_crs(
        info,
        args.pixel_coords,
        wgs84,
        &mut vertices,
        Pieces::Mesh,
        path,
        args.quiet,
    )?;
    if plan.format == MeshFormat::GeoJson && crs.epsg == Some(4326) {
        snap_to_antimeridian(&mut vertices);
    }
    if let (Some(world), Some(crs_of_raster), Some(4326)) = (&world, projected, crs.epsg) {
        check_wgs84_maps_back(world, &vertices, crs_of_raster, path)?;
        check_no_fold_in_lon_lat(&vertices, triangles, path)?;
    }
    if let Some(origin) = plan.origin {
        check_positions_map_back(&vertices, origin, info, args)?;
    }
    let options = WriteOptions::new()
        .with_origin(plan.origin)
        .with_base(args.export.base)
        .with_normals(args.export.normals);
    let mesh = MeshRef::new(&vertices, triangles)
        .with_crs_wkt(crs.wkt)
        .with_epsg(crs.epsg);
    tinsmith_export::write_mesh_with(path, plan.format, mesh, &options)?;
    let crs_written = crs.wkt.is_some_and(|w| !w.trim().is_empty());
    crate::output::note_prj_left_beside(path, plan.format, crs_written, args.quiet);
    Ok(())
}

/// The CRS a file written from `raster` records: none with `--pixel-coords` or without a
/// geotransform, else the raster's. With `wgs84` (GeoJSON without `--geojson-source-crs`,
/// for `mesh` and `contour` alike) a raster with a CRS has `points` (file coordinates)
/// reprojected in place to WGS84 longitude, latitude (RFC 7946), heights unchanged, and
/// the file records EPSG 4326; without a CRS the points stay as they are, with a note on
/// stderr unless `quiet`.
pub fn file_crs<'r>(
    info: &'r RasterInfo,
    pixel_coords: bool,
    wgs84: bool,
    points: &mut [[f64; 3]],
    pieces: Pieces<'_>,
    path: &Path,
    quiet: bool,
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
            if !quiet {
                note!(
                    "{}: no CRS, so the coordinates are written as they are, with \"crs\": null",
                    path.display()
                );
            }
            Ok(crs)
        }
    }
}

/// Notes (unless quiet) that STL and glTF, formats for 3D viewers and printers, get
/// positions in degrees beside heights in metres from a geographic raster: true to the
/// raster, but drawn stretched by about 100,000 vertically.
fn note_degrees_in_a_3d_format(info: &RasterInfo, georef: &Georef, args: &MeshArgs) -> Result<()> {
    let Georef::World(_) = georef else {
        return Ok(());
    };
    let geographic = match info.crs_wkt.as_deref() {
        Some(wkt) => is_geographic(info, wkt)?,
        None => false,
    };
    if geographic && !args.quiet {
        note!(
            "{}: the raster's CRS is geographic, so x and y are written in degrees and z in \
             its height unit: a 3D viewer draws the TIN stretched (for true proportions, \
             reproject the raster to a projected CRS first, e.g. with gdalwarp -t_srs)",
            out(args).display()
        );
    }
    Ok(())
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
fn check_wgs84_mesh_possible(info: &RasterInfo, path: &Path) -> Result<()> {
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
fn projected_crs(info: &RasterInfo) -> Result<Option<(&str, tinsmith_core::GeoTransform)>> {
    let (Some(wkt), Some(transform)) = (info.crs_wkt.as_deref(), info.transform()) else {
        return Ok(None);
    };
    Ok((!is_geographic(info, wkt)?).then_some((wkt, transform)))
}

/// Whether the raster's CRS, `wkt`, is EPSG:4326 or another geographic one.
fn is_geographic(info: &RasterInfo, wkt: &str) -> Result<bool> {
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
fn check_wgs84_maps_back(
    world: &[[f64; 3]],
    lon_lat: &[[f64; 3]],
    (wkt, transform): (&str, tinsmith_core::GeoTransform),
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
fn check_no_fold_in_lon_lat(
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

/// Memory the FlatGeobuf writer takes per triangle on top of the mesh (its spatial index and
/// the features it reorders along the index), rounded up from 136 bytes measured on
/// ETOPO5 (9.4 M triangles) and 153 on a 16384² raster (35.8 M).
const FLATGEOBUF_BYTES_PER_TRIANGLE: u64 = 160;

/// Fails, naming `path`, when writing `triangles` triangles as FlatGeobuf would take more
/// memory than is available (it was killed partway, or took the machine's swap, where a
/// 100 M-triangle mesh needed about 16 GB); the streamed formats need none.
fn check_flatgeobuf_fits(path: &Path, triangles: usize) -> Result<()> {
    let needed = (triangles as u64).saturating_mul(FLATGEOBUF_BYTES_PER_TRIANGLE);
    crate::memory::check_fits(needed, |needed, available| {
        format!(
            "{}: writing {triangles} triangles as FlatGeobuf needs about {needed:.1} GB for \
             its spatial index, and {available:.1} GB is available; write .ply or .obj \
             (streamed to disk), or give a larger --max-error",
            path.display()
        )
    })
}

/// The last gate for float32 files: every stored position maps back to a sample centre
/// as `tinsmith verify` will map it.
fn check_positions_map_back(
    vertices: &[[f64; 3]],
    origin: LocalOrigin,
    info: &RasterInfo,
    args: &MeshArgs,
) -> Result<()> {
    let georef = Georef::new(info.transform(), args.pixel_coords);
    for (i, &v) in vertices.iter().enumerate() {
        let q = origin.quantize(v);
        let tolerance = crate::georef::F32_SAMPLE_TOLERANCE;
        georef.sample_at([q[0], q[1]], tolerance).with_context(|| {
            format!(
                "{}: vertex {i} would not map back to its sample in float32; nothing written",
                out(args).display()
            )
        })?;
    }
    Ok(())
}

/// `--format NAME`.
pub fn parse_format(name: &str) -> std::result::Result<MeshFormat, String> {
    MeshFormat::from_name(name).map_err(|e| e.to_string())
}

/// The output path of a `mesh` run that writes one file (`--per-tile` runs do not come
/// here).
fn out(args: &MeshArgs) -> &std::path::Path {
    args.output.as_deref().unwrap_or(std::path::Path::new("-"))
}
