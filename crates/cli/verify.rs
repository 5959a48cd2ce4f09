//! `tinsmith verify`: measure a mesh file's true error against its raster.

use anyhow::{Context, Result};
use tinsmith_georef::Placement;
use tinsmith_verify::{GridRef, MeshRef, Report, VerifyOptions};

use crate::args::VerifyArgs;
use crate::mesh_file::{
    expected_orientation, mesh_format, orient_polygon_triangles, read_mesh_file, sample_positions,
};
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
    let raster = tinsmith_raster::read_samples(&args.input, args.band)?;
    crate::transform_check::check_transform(&raster.info, args.pixel_coords)?;
    let georef = Placement::new(raster.info.transform(), args.pixel_coords);
    let mesh = read_mesh_file(&args.mesh, format, &raster, georef)?;
    let positions = sample_positions(&args.mesh, &mesh, format, &raster, georef)?;
    let heights: Vec<f64> = mesh.vertices.iter().map(|v| v[2]).collect();
    let orientation = expected_orientation(&georef);
    let mut triangles = mesh.triangles;
    orient_polygon_triangles(format, &positions, &mut triangles, orientation);
    let grid = &raster.samples;
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
