//! `tinsmith verify`: measure a mesh file's true error against its raster.

use std::path::Path;

use anyhow::{Context, Result};
use tinsmith_export::Mesh;
use tinsmith_raster::Raster;
use tinsmith_verify::{GridRef, MeshRef, Orientation, Report, VerifyOptions};

use crate::args::VerifyArgs;
use crate::georef::Georef;
use crate::number::readable;

/// Runs the verifier; `Ok(false)` when the mesh is invalid or exceeds `--max-error`.
pub fn run(args: &VerifyArgs) -> Result<bool> {
    crate::memory::check_whole_raster_fits(
        &args.input,
        crate::memory::raster_size(&args.input, args.band)?,
        crate::memory::Need {
            bytes_per_sample: 24,
            extra_bytes: 2 * crate::memory::file_bytes(&args.mesh),
        },
        "verify",
        "verification has no tiled mode; use a machine with more memory",
    )?;
    let raster = tinsmith_raster::read_grid(&args.input, args.band)?;
    let georef = Georef::new(raster.info.transform(), args.pixel_coords);
    let mesh = read_mesh_file(&args.mesh, &raster, georef)?;
    let mut positions = Vec::with_capacity(mesh.vertices.len());
    for (i, v) in mesh.vertices.iter().enumerate() {
        let p = georef
            .sample_at([v[0], v[1]])
            .with_context(|| format!("{}: vertex {i}", args.mesh.display()))?;
        positions.push(p);
    }
    let heights: Vec<f64> = mesh.vertices.iter().map(|v| v[2]).collect();
    let grid = &raster.grid;
    let mut options = VerifyOptions::new().with_orientation(expected_orientation(&georef));
    if let Some(e) = args.max_error {
        options = options.with_max_error(e);
    }
    let report = tinsmith_verify::verify(
        GridRef::new(grid.width(), grid.height(), grid.values()),
        MeshRef::new(&positions, &heights, &mesh.triangles),
        &options,
    )
    .with_context(|| format!("{}: cannot verify", args.mesh.display()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report, args);
    }
    Ok(report.passed())
}

/// Reads a mesh file written from `raster` in its file coordinates: RFC 7946 GeoJSON
/// (WGS84 longitude, latitude) is transformed back to the raster's CRS.
///
/// Longitudes in WGS84 files are in [-180, 180] (RFC 7946); for a geographic raster they
/// are moved by whole turns into the raster's own range (0..360 for many global grids).
pub fn read_mesh_file(path: &Path, raster: &Raster, georef: Georef) -> Result<Mesh> {
    let mut mesh = tinsmith_export::read_mesh(path)?;
    if let (Some(4326), Georef::World(transform), Some(wkt)) =
        (mesh.epsg, georef, raster.info.crs_wkt.as_deref())
    {
        if raster.info.epsg != Some(4326) {
            tinsmith_raster::from_wgs84(wkt, &mut mesh.vertices).with_context(|| {
                format!(
                    "{}: cannot transform WGS84 back to the raster's CRS",
                    path.display()
                )
            })?;
        }
        if tinsmith_raster::is_geographic(wkt)? {
            let (w, h) = (raster.info.width as f64, raster.info.height as f64);
            let west = [
                (-0.5, -0.5),
                (w - 0.5, -0.5),
                (-0.5, h - 0.5),
                (w - 0.5, h - 0.5),
            ]
            .into_iter()
            .map(|(x, y)| transform.sample_centre(x, y)[0])
            .fold(f64::INFINITY, f64::min);
            for v in &mut mesh.vertices {
                if v[0] < west || v[0] >= west + 360.0 {
                    v[0] = west + (v[0] - west).rem_euclid(360.0);
                }
            }
        }
    }
    Ok(mesh)
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
