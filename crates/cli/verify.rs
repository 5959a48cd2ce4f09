//! `tinsmith verify`: measure a mesh file's true error against its raster.

use std::path::Path;

use anyhow::{Context, Result};
use tinsmith_export::{Mesh, MeshFormat};
use tinsmith_raster::Raster;
use tinsmith_verify::{GridRef, MeshRef, Orientation, Report, VerifyOptions};

use crate::args::VerifyArgs;
use crate::georef::Georef;
use crate::number::readable;

/// Runs the verifier; `Ok(false)` when the mesh is invalid or exceeds `--max-error`.
pub fn run(args: &VerifyArgs) -> Result<bool> {
    let format = mesh_format(&args.mesh, args.format)?;
    crate::memory::check_whole_raster_fits(
        &args.input,
        crate::memory::raster_size(&args.input, args.band)?,
        crate::memory::Need {
            bytes_per_sample: 24,
            extra_bytes: crate::memory::mesh_file_memory(&args.mesh, format),
        },
        "verify",
        "verification has no tiled mode; use a machine with more memory",
    )?;
    let raster = tinsmith_raster::read_grid(&args.input, args.band)?;
    crate::georef::check_transform(&raster.info, args.pixel_coords)?;
    let georef = Georef::new(raster.info.transform(), args.pixel_coords);
    let mesh = read_mesh_file(&args.mesh, format, &raster, georef)?;
    let positions = sample_positions(&args.mesh, &mesh, format, &raster, georef)?;
    let heights: Vec<f64> = mesh.vertices.iter().map(|v| v[2]).collect();
    let orientation = expected_orientation(&georef);
    let mut triangles = mesh.triangles;
    orient_polygon_triangles(format, &positions, &mut triangles, orientation);
    let grid = &raster.grid;
    let mut options = VerifyOptions::new().with_orientation(orientation);
    if let Some(e) = args.max_error {
        options = options.with_max_error(e);
    }
    let report = tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &heights, &triangles),
        &options,
    )
    .with_context(|| format!("{}: cannot verify", args.mesh.display()))?;
    if report.domain_samples == 0 {
        // `mesh` refuses such a raster: a pass here would measure nothing.
        anyhow::bail!(
            "{}: has no valid cell (a 2 x 2 block of valid samples), so no triangle can \
             cover any of its {} valid samples and there is nothing to measure",
            args.input.display(),
            report.valid_samples
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report, args);
    }
    if !report.passed() && raster.info.band_count > 1 {
        note!(
            "{}: note: verified against band {} of {}; a mesh of another band fails here \
             (--band picks another)",
            args.mesh.display(),
            args.band,
            raster.info.band_count
        );
    }
    Ok(report.passed())
}

/// Reads a mesh file written from `raster` in its file coordinates: RFC 7946 GeoJSON
/// (WGS84 longitude, latitude) is transformed back to the raster's CRS.
///
/// Longitudes in WGS84 files are in [-180, 180] (RFC 7946); for a geographic raster they
/// are moved by whole turns into the raster's own range (0..360 for many global grids).
pub fn read_mesh_file(
    path: &Path,
    format: MeshFormat,
    raster: &Raster,
    georef: Georef,
) -> Result<Mesh> {
    let mut mesh = tinsmith_export::read_mesh_as(path, format)?;
    let polygons = is_polygon_format(format);
    // A GIS rewrite may keep WGS84 as WKT alone (a shapefile's GCS_WGS_1984).
    if polygons
        && mesh.epsg.is_none()
        && mesh.crs_wkt != raster.info.crs_wkt
        && mesh
            .crs_wkt
            .as_deref()
            .is_some_and(tinsmith_raster::is_wgs84_lon_lat)
    {
        mesh.epsg = Some(4326);
    }
    if let (Some(4326), Georef::World(transform), Some(wkt)) =
        (mesh.epsg, georef, raster.info.crs_wkt.as_deref())
    {
        if transformed_from_wgs84(&mesh, raster, georef) {
            tinsmith_raster::from_wgs84(wkt, &mut mesh.vertices).with_context(|| {
                format!(
                    "{}: cannot transform WGS84 back to the raster's CRS",
                    path.display()
                )
            })?;
        }
        if tinsmith_raster::is_geographic(wkt)? {
            if polygons {
                // Placing triangles around the raster's seam needs them counter-clockwise
                // in longitude, latitude, as tinsmith writes them.
                counter_clockwise_in_lon_lat(&mut mesh);
            }
            into_raster_frame(&mut mesh, raster, transform);
        }
    }
    Ok(mesh)
}

/// The sample (column, row) under each vertex of `mesh`, read from `path` in `format`;
/// fails naming the first vertex that is not on a sample centre, to within the rounding
/// of the format's positions (see [`position_tolerance`]).
pub fn sample_positions(
    path: &Path,
    mesh: &Mesh,
    format: MeshFormat,
    raster: &Raster,
    georef: Georef,
) -> Result<Vec<[i64; 2]>> {
    let tolerance = position_tolerance(format, mesh, raster, georef);
    mesh.vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            georef
                .sample_at([v[0], v[1]], tolerance)
                .with_context(|| format!("{}: vertex {i}", path.display()))
        })
        .collect()
}

/// How far (in pixels) a vertex of `mesh`, read in `format`, may be from its sample
/// centre: the rounding of float32 positions for STL and glTF, of the transforms for a
/// GeoJSON file in WGS84 read back into a projected raster's CRS, else of `f64`. A vertex
/// further off is not taken for its sample: verify measures the mesh as written.
pub fn position_tolerance(format: MeshFormat, mesh: &Mesh, raster: &Raster, georef: Georef) -> f64 {
    use crate::georef::{F32_SAMPLE_TOLERANCE, F64_SAMPLE_TOLERANCE, WGS84_SAMPLE_TOLERANCE};
    if format.is_float32() {
        F32_SAMPLE_TOLERANCE
    } else if transformed_from_wgs84(mesh, raster, georef) {
        WGS84_SAMPLE_TOLERANCE
    } else {
        F64_SAMPLE_TOLERANCE
    }
}

/// Whether [`read_mesh_file`] transforms `mesh`'s vertices from WGS84 into the raster's
/// CRS: a WGS84 mesh, world coordinates, and a raster with a CRS of its own other than
/// EPSG:4326.
fn transformed_from_wgs84(mesh: &Mesh, raster: &Raster, georef: Georef) -> bool {
    mesh.epsg == Some(4326)
        && matches!(georef, Georef::World(_))
        && raster.info.epsg != Some(4326)
        && raster.info.crs_wkt.is_some()
}

/// Moves longitudes read from RFC 7946 GeoJSON (in [-180, 180]) by whole turns into a
/// geographic raster's own frame (0..360 for many global grids), triangle by triangle:
/// the whole triangle by the shift that puts it inside the raster's extent, counter-
/// clockwise, when there is one; otherwise a corner outside the raster's extent into
/// [west, west + 360), then, of the placements with corners a turn further east where that
/// stays within the raster (the east edge of a grid whose first and last columns are the
/// same meridian), the counter-clockwise one spanning the fewest degrees; corners are then
/// welded again by position.
fn into_raster_frame(mesh: &mut Mesh, raster: &Raster, transform: tinsmith_core::GeoTransform) {
    let (w, h) = (f64::from(raster.info.width), f64::from(raster.info.height));
    let xs: Vec<f64> = [
        (-0.5, -0.5),
        (w - 0.5, -0.5),
        (-0.5, h - 0.5),
        (w - 0.5, h - 0.5),
    ]
    .into_iter()
    .map(|(x, y)| transform.sample_centre(x, y)[0])
    .collect();
    let west = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let east = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let base = |lon: f64| {
        if lon < west || lon > east {
            west + (lon - west).rem_euclid(360.0)
        } else {
            lon
        }
    };
    let mut welded: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let mut vertices: Vec<[f64; 3]> = Vec::with_capacity(mesh.vertices.len());
    let ccw = |lons: [f64; 3], corners: &[[f64; 3]; 3]| {
        let [a, b, c] = [0, 1, 2].map(|k| [lons[k], corners[k][1]]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
    };
    for triangle in &mut mesh.triangles {
        let corners = triangle.map(|i| mesh.vertices[i as usize]);
        // The writers move each triangle (or cut part) as a whole by turns into
        // [-180, 180]: the whole-turn shift that puts it back inside the raster is the
        // one (a second would need a triangle no wider than the columns the raster
        // repeats). Only when none fits are corners placed one by one.
        let whole = [0.0, 1.0, -1.0, 2.0, -2.0]
            .into_iter()
            .map(|turns| corners.map(|v| v[0] + 360.0 * turns))
            .find(|lons| lons.iter().all(|&l| l >= west && l <= east) && ccw(*lons, &corners));
        let placed = whole.unwrap_or_else(|| {
            let lons = corners.map(|v| base(v[0]));
            // Of the placements (each corner as is, or a turn east if that stays within
            // the raster), the counter-clockwise one (as written) spanning the fewest
            // degrees.
            let mut best: Option<(f64, [f64; 3])> = None;
            for turns in 0..8u32 {
                let placed = [0, 1, 2].map(|k| lons[k] + 360.0 * f64::from((turns >> k) & 1));
                if placed.iter().any(|&lon| lon > east) || !ccw(placed, &corners) {
                    continue;
                }
                let span = placed.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - placed.iter().copied().fold(f64::INFINITY, f64::min);
                if best.is_none_or(|(s, _)| span < s) {
                    best = Some((span, placed));
                }
            }
            best.map_or(lons, |(_, placed)| placed)
        });
        for (index, lon) in triangle.iter_mut().zip(placed) {
            let v = mesh.vertices[*index as usize];
            let p = [lon, v[1], v[2]];
            *index = *welded.entry(p.map(f64::to_bits)).or_insert_with(|| {
                vertices.push(p);
                (vertices.len() - 1) as u32
            });
        }
    }
    mesh.vertices = vertices;
}

/// The format of the mesh file at `path`: `given` (a `--format` option), or the one its
/// extension names.
pub fn mesh_format(path: &Path, given: Option<MeshFormat>) -> Result<MeshFormat> {
    match given {
        Some(format) => Ok(format),
        None => Ok(MeshFormat::from_path(path)?),
    }
}

/// Whether `format` is GeoJSON or FlatGeobuf: triangles stored as polygons, whose winding
/// says nothing (see [`orient_polygon_triangles`]).
fn is_polygon_format(format: MeshFormat) -> bool {
    matches!(format, MeshFormat::GeoJson | MeshFormat::FlatGeobuf)
}

/// Reverses every triangle when most are clockwise in longitude, latitude as written (a
/// file wound the other way round, as shapefiles wind polygons). Triangle by triangle the
/// winding cannot be told near the raster's seam or a pole, where a triangle may span
/// more than half a turn; across the file it can.
fn counter_clockwise_in_lon_lat(mesh: &mut Mesh) {
    let (mut cw, mut ccw) = (0usize, 0usize);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
        let area_x2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area_x2 < 0.0 {
            cw += 1;
        } else if area_x2 > 0.0 {
            ccw += 1;
        }
    }
    if cw > ccw {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
}

/// Turns each triangle of a GeoJSON or FlatGeobuf mesh (`positions` on the grid) to
/// `orientation`: those formats hold triangles as polygons, whose winding says nothing
/// (RFC 7946 asks readers not to reject rings against its right-hand rule; shapefiles wind
/// them clockwise), so a triangle wound the other way is the same triangle. Other formats
/// are left as they are: their winding says which way a face points.
pub fn orient_polygon_triangles(
    format: MeshFormat,
    positions: &[[i64; 2]],
    triangles: &mut [[u32; 3]],
    orientation: Orientation,
) {
    if !is_polygon_format(format) {
        return;
    }
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize].map(i128::from));
        let area_x2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area_x2.signum() == -orientation.sign() {
            t.swap(1, 2);
        }
    }
}

/// Mesh files hold triangles counter-clockwise in file coordinates (normals up), which is
/// clockwise in grid coordinates when the georeference flips orientation.
pub fn expected_orientation(georef: &Georef) -> Orientation {
    if georef.flips_orientation() {
        Orientation::Clockwise
    } else {
        Orientation::CounterClockwise
    }
}

fn print_report(report: &Report, args: &VerifyArgs) {
    println!(
        "mesh:            {} ({} vertices, {} triangles)",
        args.mesh.display(),
        report.vertices,
        report.triangles
    );
    println!(
        "raster:          {} ({} x {}, {} valid samples)",
        args.input.display(),
        report.width,
        report.height,
        report.valid_samples
    );
    match &report.max_error_at {
        Some(at) => println!(
            "max error:       {} at column {}, row {} (sample {}, TIN {})",
            readable(report.max_error),
            at.x,
            at.y,
            readable(at.sample),
            readable(at.interpolated)
        ),
        None => println!("max error:       {}", readable(report.max_error)),
    }
    if let Some(e) = report.max_error_allowed {
        println!("allowed:         {}", readable(e));
    }
    if report.isolated_samples > 0 {
        println!(
            "isolated:        {} valid samples in no 2x2 block of valid samples (no triangle \
             can hold them; not checked)",
            report.isolated_samples
        );
    }
    println!(
        "mesh valid:      {}",
        if report.mesh_is_valid() { "yes" } else { "NO" }
    );
    for p in &report.problems {
        println!("problem:         {p}");
    }
    println!(
        "result:          {}",
        if report.passed() { "PASS" } else { "FAIL" }
    );
}
