//! `tinsmith mesh`: decimate a raster into a TIN, check it, write it.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tinsmith_core::{decimate_with_progress, Grid};
use tinsmith_formats::{MeshFormat, VertexAttribute};
use tinsmith_georef::Placement;
use tinsmith_tiling::check_tin;

use crate::error::{bail, Context};
use crate::jobs::MeshJob;
use crate::output_paths::NamingFile;
use crate::output_paths::{check_distinct, check_writable_target, ReservedReport};
use crate::report::{MeshSummary, Outcome, Seconds};
use crate::Feedback;
use crate::Result;

/// The `--report` JSON.
#[derive(Debug, Serialize)]
struct MeshReport<'a> {
    #[serde(flatten)]
    summary: MeshSummary<'a>,
    #[serde(flatten)]
    output_format: crate::format_plan::PlanReport,
    /// Vertices of the mesh decimation started from (the start's, see `--initial-mesh`).
    start_vertices: usize,
    /// Sweeps until nothing could be removed (the greedy order counts as one).
    sweeps: usize,
    /// Removal attempts in all.
    removal_attempts: usize,
    /// Each variable's bound and measured error (`--bands`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    variables: Vec<crate::VariableReport>,
    seconds: Seconds,
}

/// Reads, decimates, verifies in memory and writes (tile by tile when the raster is larger
/// than `job.tile_size` or with `job.per_tile`); the mesh is written only if the
/// independent verifier confirms the bound, with its heights as the file holds them.
pub fn mesh(job: &MeshJob, feedback: &dyn Feedback) -> Result<()> {
    // A raster with breaklines, a boundary or a hull edge length goes the points' way:
    // its valid samples are the points of a constrained triangulation.
    if crate::points::is_point_input(&job.input)
        || job.points.breaklines.is_some()
        || job.points.boundary.is_some()
        || job.points.hull_edge_length.is_some()
    {
        return crate::points::mesh_points(job, feedback);
    }
    if job.tile_format.is_some() && job.per_tile.is_none() {
        bail!(
            "--tile-format sets the format of the --per-tile files; without --per-tile the \
             format follows -o's extension (or --format)"
        );
    }
    if job.per_tile.is_some() {
        let export = &job.export;
        let ignored = [
            (
                export.format.is_some(),
                "--format (use --tile-format ply or obj)",
            ),
            (export.base.is_some(), "--base (STL only)"),
            (export.normals, "--normals (glTF only)"),
            (
                export.geojson_source_crs,
                "--geojson-source-crs (GeoJSON only)",
            ),
        ];
        if let Some((_, option)) = ignored.iter().find(|(given, _)| *given) {
            bail!(
                "{option} does not apply to --per-tile, which writes PLY or OBJ files (--tile-format)"
            );
        }
    }
    if let Some(png) = &job.preview {
        crate::preview::check_picture_path(png, PREVIEW_SIZE)?;
        crate::output_paths::check_writable_target(png, &job.input)?;
        if job.per_tile.is_some() {
            bail!("--preview draws one mesh; --per-tile writes many");
        }
    }
    let Some(output) = crate::tiled_mesh::untiled_output(job)? else {
        if !job.variables.is_empty() {
            crate::variables::check_tiled(job)?;
        }
        let Some(png) = &job.preview else {
            return crate::tiled_mesh::run(job, feedback);
        };
        // A tiled mesh is drawn from the file once written, the whole raster read again:
        // refused now if that would not fit.
        let output = job
            .output
            .as_deref()
            .expect("a tiled run without --per-tile has -o");
        let mut picture = crate::PreviewJob::new(&job.input, output, png);
        picture.format = job.export.format;
        picture.band = job.band;
        picture.pixel_coords = job.pixel_coords;
        picture.vertical_datum = job.vertical_datum.clone();
        picture.variables = job.variables.clone();
        picture.size = PREVIEW_SIZE;
        crate::preview::check_fits(&picture)?;
        crate::tiled_mesh::run(job, feedback)?;
        crate::preview(&picture)?;
        return Ok(());
    };
    if let Some(png) = &job.preview {
        let others = [Some(output), job.report.as_deref()];
        for other in others.into_iter().flatten() {
            if other == png.as_path() {
                bail!("{}: --preview names another output too", png.display());
            }
            crate::output_paths::check_distinct(other, png, "another output")?;
        }
    }
    let total = Instant::now();
    // `untiled_output` has checked the output path and its sidecar.
    let format = crate::format_plan::format(job)?;
    if !job.variables.is_empty() {
        // OBJ carries three 8-bit bands as vertex colours: checked once they are read.
        if !format.carries_attributes() && format != MeshFormat::Obj {
            bail!(
                "{}: {format} carries heights only; the variables of --bands are written \
                 to PLY (.ply) or glTF (.glb), one value per vertex and band, or GeoJSON \
                 and FlatGeobuf (.geojson, .fgb), each triangle's corner mean per band",
                output.display()
            );
        }
        if job.decimation.has_count_target() {
            bail!(
                "{}: --bands takes error bounds (--max-error), not --max-triangles or \
                 --max-vertices",
                job.input.display()
            );
        }
    }
    let reserved = reserve_report(job, Some((output, format)))?;

    let t = Instant::now();
    let raster = crate::mesh_file::read_raster(&job.input, job.band, job.vertical_datum.as_ref())?;
    crate::output_paths::note_gcps_unused(&raster.info, job.pixel_coords, feedback);
    let tinsmith_raster::Raster {
        samples,
        info: raster_info,
        ..
    } = raster;
    let (grid, variables, rgb) = if job.variables.is_empty() {
        (Grid::from_samples(samples), Vec::new(), false)
    } else {
        crate::variables::read(
            &job.input,
            (samples, &raster_info),
            &job.variables,
            format.is_float32(),
        )?
    };
    let grid = &grid;
    if format == MeshFormat::Obj && !variables.is_empty() && !rgb {
        bail!(
            "{}: OBJ carries three 8-bit bands as vertex colours (v x y z r g b) and no other \
             variables; write PLY (.ply) or glTF (.glb) for these",
            output.display()
        );
    }
    let read_seconds = t.elapsed().as_secs_f64();
    if grid.valid_cell_count() == 0 {
        bail!(
            "{}: band {} has no 2x2 block of valid samples, so there is nothing to triangulate",
            job.input.display(),
            job.band
        );
    }

    let max_error = job.decimation.max_error.unwrap_or(f64::INFINITY);
    let plan =
        crate::format_plan::FormatPlan::new(format, &raster_info, Some(grid), job, feedback)?;
    // Float32 formats leave the decimator the bound less their height rounding.
    let heights = raster_info.min.zip(raster_info.max);
    crate::report::note_rounding_margin(&job.input, plan.decimation_bound, heights, feedback);
    let options = job
        .decimation_options(plan.decimation_bound, heights)
        .naming_file(&job.input)?;
    let result = decimate_with_progress(grid, &options, &mut |p| match p.sweep {
        0 => feedback.status("decimating: building the start mesh"),
        _ => feedback.status(&format!(
            "decimating: sweep {}, {:3.0}% of its vertices tried, {} removed",
            p.sweep,
            100.0 * p.sweep_fraction,
            p.removed
        )),
    })
    .naming_file(&job.input)?;
    feedback.clear_status();
    let tin = &result.tin;

    // The promise is checked, independently, before anything is written.
    let placement = Placement::new(raster_info.transform(), job.pixel_coords);
    let t = Instant::now();
    // The heights as the file will hold them (float32 formats round them).
    let check = check_tin(grid, tin, |_, v| plan.file_height(v.z), max_error)?;
    if !check.passed() {
        bail!(
            "{}: internal error, the decimated mesh failed verification ({}); nothing written",
            job.input.display(),
            check.problems.join("; ")
        );
    }
    let at_vertices = crate::variables::vertex_values(grid, tin, format.is_float32());
    let variable_reports =
        crate::variables::check(&job.input, grid, &variables, tin, &at_vertices)?;
    let verify_seconds = t.elapsed().as_secs_f64();

    // Drawn before anything is written, so that a picture that cannot be made leaves the
    // old outputs alone.
    let picture = match &job.preview {
        Some(_) => Some(draw_preview(job, output, &raster_info, grid, tin)?),
        None => None,
    };

    let t = Instant::now();
    let (vertices, triangles) = placement.file_mesh(
        tin.vertices().iter().map(|v| (v.x, v.y, v.z)),
        tin.triangles().iter().copied(),
    );
    let attributes: Vec<VertexAttribute<'_>> = variables
        .iter()
        .zip(&at_vertices)
        .map(|((_, name), values)| VertexAttribute { name, values })
        .filter(|_| format != MeshFormat::Obj)
        .collect();
    // Three 8-bit bands are colours too, in the formats that have vertex colours.
    let colours: Option<Vec<[u8; 3]>> =
        (rgb && matches!(format, MeshFormat::Ply | MeshFormat::Glb | MeshFormat::Obj)).then(|| {
            (0..tin.vertices().len())
                .map(|i| [0, 1, 2].map(|k| at_vertices[k][i] as u8))
                .collect()
        });
    crate::format_plan::write(
        &plan,
        job,
        &raster_info,
        (vertices, &triangles),
        (&attributes, colours.as_deref()),
        feedback,
    )?;
    if let (Some(png), Some(bytes)) = (&job.preview, &picture) {
        tinsmith_output::write_bytes_atomically(png, bytes)
            .with_context(|| format!("{}: cannot write", png.display()))?;
    }
    let write_seconds = t.elapsed().as_secs_f64();

    let r = &result.report;
    let outcome = Outcome {
        size: (grid.width(), grid.height()),
        // With variables, the samples valid in every band.
        valid_samples: match variables.is_empty() {
            true => raster_info.valid_samples,
            false => grid.valid_count() as u64,
        },
        band_count: raster_info.band_count,
        before: (r.initial_triangles as u64, r.initial_vertices as u64),
        after: (r.final_triangles as u64, r.final_vertices as u64),
        max_error_bound: r.max_bound,
        measured_max_error: check.max_error,
        vertex_heights_raised: options.raises_vertex_heights(grid.max_abs_value()),
    };
    let report = MeshReport {
        summary: MeshSummary::new(job, output, outcome),
        output_format: plan.report(),
        start_vertices: r.start_vertices,
        sweeps: r.sweeps,
        removal_attempts: r.attempts,
        variables: variable_reports,
        seconds: Seconds {
            read: read_seconds,
            initial_mesh: r.seconds_initial_mesh,
            decimate: r.seconds_decimation,
            verify: verify_seconds,
            write: write_seconds,
            total: total.elapsed().as_secs_f64(),
        },
    };
    report.summary.print("", feedback);
    for v in &report.variables {
        feedback.note(&format!(
            "{}: band {} ({}) measured max error {} <= {}",
            output.display(),
            v.band,
            v.name,
            tinsmith_georef::readable(v.measured_max_error),
            tinsmith_georef::readable(v.max_error)
        ));
    }
    plan.note_origin(output, feedback);
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&report)?)?;
    }
    tinsmith_output::mark_finished();
    Ok(())
}

/// The longer side of `--preview`'s picture, in pixels.
const PREVIEW_SIZE: u32 = 1600;

/// `--preview`'s PNG of `tin` (verified, largest error `max_error`) over `grid`, as
/// `tinsmith preview` draws the mesh file `output`.
fn draw_preview(
    job: &MeshJob,
    output: &Path,
    info: &tinsmith_raster::RasterInfo,
    grid: &Grid,
    tin: &tinsmith_core::Tin,
) -> Result<Vec<u8>> {
    let positions: Vec<[i64; 2]> = tin
        .vertices()
        .iter()
        .map(|v| [i64::from(v.x), i64::from(v.y)])
        .collect();
    let heights: Vec<f64> = tin.vertices().iter().map(|v| v.z).collect();
    let drawn = tinsmith_preview::DrawnSamples::new(grid.width(), grid.height(), PREVIEW_SIZE)?;
    let values = crate::preview::drawn_values(grid.values(), grid.width() as usize, &drawn);
    let drawing = crate::preview::Drawing {
        input: &job.input,
        info,
        drawn: &drawn,
        values: &values,
        positions: &positions,
        heights: &heights,
        triangles: tin.triangles(),
        mesh_label: output.display().to_string(),
    };
    let choices = crate::preview::PictureChoices {
        size: PREVIEW_SIZE,
        hillshade: true,
        wireframe: true,
        error: false,
        max_error: None,
    };
    Ok(drawing.png(&choices)?.1)
}

/// Checks `--report` before the work (writable; not the input, the output, its `.prj`
/// sidecar, or inside the `--per-tile` directory) and takes its room (see
/// [`ReservedReport`]); `None` without `--report`.
pub fn reserve_report(
    job: &MeshJob,
    output: Option<(&Path, MeshFormat)>,
) -> Result<Option<ReservedReport>> {
    let Some(report) = &job.report else {
        return Ok(None);
    };
    if let Some(dir) = &job.per_tile {
        crate::output_paths::check_not_inside(dir, report, "the --per-tile directory")?;
    }
    check_writable_target(report, &job.input)?;
    if let Some((output, format)) = output {
        check_distinct(output, report, "the output")?;
        crate::output_paths::check_distinct_from_sidecar(output, report, format, job.pixel_coords)?;
    }
    Ok(Some(ReservedReport::reserve(report)?))
}
