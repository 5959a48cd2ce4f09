//! `tinsmith mesh` on rasters larger than one tile (or with `--per-tile`): the tiled
//! engine of `tinsmith-tiling`, with tile progress and the same report as the untiled path
//! plus the tile fields.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use tinsmith_formats::MeshFormat;
use tinsmith_georef::Placement;
use tinsmith_tiling::{
    mesh_tiles, MeshCollector, PerTileWriter, RasterSource, TileOptions, TilePlan, TileProgress,
    TilesReport, WeldedWriter,
};

use crate::error::bail;
use crate::jobs::{MeshJob, TileFormat};
use crate::output_paths::NamingFile;
use crate::report::{MeshSummary, Outcome, Seconds};
use crate::Feedback;
use crate::Result;

/// The output file when the untiled engine should run: no `--per-tile`, and the raster
/// fits in one tile or a triangle or vertex count is the target (which needs the whole
/// raster at once). `None` when the tiled engine should run.
pub fn untiled_output(job: &MeshJob) -> Result<Option<&Path>> {
    let Some(output) = job.output.as_deref() else {
        return Ok(None);
    };
    if job.per_tile.is_some() {
        return Ok(None);
    }
    // Checks the untiled path makes first, so that errors come in the same order.
    let format = crate::format_plan::format(job)?;
    crate::output_paths::check_writable_target(output, &job.input)?;
    let reader =
        crate::mesh_file::window_reader(&job.input, job.band, job.vertical_datum.as_ref())?;
    if !job.pixel_coords {
        // The CRS written: none for a raster without a geotransform (pixel coordinates).
        let info = reader.info();
        let crs_wkt = info
            .crs_wkt
            .as_deref()
            .filter(|_| info.transform().is_some());
        crate::output_paths::check_sidecar(output, &job.input, format, crs_wkt)?;
    }
    crate::transform_check::check_transform(reader.info(), job.pixel_coords)?;
    crate::format_plan::check_float32_positions(format, reader.info(), job)?;
    let fits = reader.width() <= job.tile_size && reader.height() <= job.tile_size;
    let count_target = job.decimation.has_count_target();
    if count_target && !fits {
        let samples = u64::from(reader.width()) * u64::from(reader.height());
        let start_triangles = job.decimation.count_target_start_triangles(samples);
        crate::memory::check_whole_raster_fits(
            &job.input,
            (reader.width(), reader.height()),
            crate::memory::Need {
                bytes_per_sample: tinsmith_tiling::COUNT_TARGET_BYTES_PER_SAMPLE,
                extra_bytes: start_triangles
                    .saturating_mul(crate::memory::BYTES_PER_START_TRIANGLE),
            },
            "a --max-triangles or --max-vertices target",
            "give --max-error instead (decimated tile by tile, in bounded memory)",
        )?;
    } else if fits {
        crate::memory::check_whole_raster_fits(
            &job.input,
            (reader.width(), reader.height()),
            crate::memory::Need {
                bytes_per_sample: tinsmith_tiling::WHOLE_GRID_BYTES_PER_SAMPLE,
                extra_bytes: 0,
            },
            "meshing in one tile (the raster fits --tile-size)",
            "give a smaller --tile-size",
        )?;
    }
    Ok((fits || count_target).then_some(output))
}

/// The `--report` JSON in tiled mode: the untiled report's fields (counts over the welded
/// mesh; per-phase seconds summed over tiles, i.e. thread-seconds; `total` wall-clock),
/// plus `tiles`.
#[derive(Debug, Serialize)]
struct TiledMeshReport<'a> {
    #[serde(flatten)]
    summary: MeshSummary<'a>,
    /// The format and float32 fields, for `-o`.
    #[serde(flatten)]
    output_format: Option<crate::format_plan::PlanReport>,
    /// Each variable's bound and measured error (`--bands`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    variables: Vec<crate::VariableReport>,
    seconds: Seconds,
    tiles: Tiles,
}

#[derive(Debug, Serialize)]
struct Tiles {
    /// Number of tiles.
    count: usize,
    /// `--tile-size`: samples per side, shared row and column included.
    size: u32,
    columns: u32,
    rows: u32,
    threads: usize,
    /// `true` for one welded mesh, `false` for `--per-tile`.
    welded: bool,
    /// Wall-clock seconds of the statistics scan (the raster-wide max |value|).
    scan_seconds: f64,
    /// Wall-clock seconds from the first tile read to the last tile written.
    tiles_seconds: f64,
}

/// Meshes the raster tile by tile into one welded mesh (`-o`) or one file per tile
/// (`--per-tile`); every tile is verified before it is written.
pub fn run(job: &MeshJob, feedback: &dyn Feedback) -> Result<()> {
    let total = Instant::now();
    let input = job.input.display();
    if job.decimation.has_count_target() {
        bail!(
            "{input}: --max-triangles and --max-vertices need the whole raster at once, and \
             --per-tile meshes it tile by tile; give --max-error"
        );
    }
    let Some(max_error) = job.decimation.max_error else {
        bail!("{input}: tiles need --max-error");
    };
    // With -o, `untiled_output` has checked the output path, its sidecar and the
    // geotransform; --per-tile has not been through it.
    let welded_format = match &job.output {
        Some(_) => Some(crate::format_plan::format(job)?),
        None => {
            crate::transform_check::check_input_transform(&job.input, job.band, job.pixel_coords)?;
            None
        }
    };
    let welded_output = job.output.as_deref().zip(welded_format);
    let reserved = crate::mesh::reserve_report(job, welded_output)?;

    let t = Instant::now();
    let info =
        crate::scan::scan_raster(&job.input, job.band, job.vertical_datum.as_ref(), feedback)?;
    crate::output_paths::note_gcps_unused(&info, job.pixel_coords, feedback);
    let source = RasterSource::new(&info)?;
    // `_resampled`: the --attributes files put on the input's grid, read until the end.
    let (source, variables, largest, _resampled) = if job.variables.is_empty() {
        (source, Vec::new(), Vec::new(), Vec::new())
    } else {
        let v = crate::variables::tiled_source(&job.input, (source, &info), &job.variables)?;
        (v.source, v.named, v.largest, v.resampled)
    };
    let scan_seconds = t.elapsed().as_secs_f64();
    let plan = TilePlan::new(info.width, info.height, job.tile_size).naming_file(&job.input)?;
    feedback.tiles_start("tiles");
    feedback.tiles_done(0, plan.len() as u64);

    // Float32 formats leave the decimator the bound less their height rounding.
    let export_plan = match welded_format {
        Some(format) => Some(crate::format_plan::FormatPlan::new(
            format, &info, None, job, feedback,
        )?),
        None => None,
    };
    let bound = export_plan.map_or(max_error, |p| p.decimation_bound);
    let heights = info.min.zip(info.max);
    crate::report::note_rounding_margin(&job.input, bound, heights, feedback);
    let decimation = job
        .decimation_options(bound, heights)
        .naming_file(&job.input)?;
    let vertex_heights_raised =
        decimation.raises_vertex_heights(info.max_abs_value().unwrap_or(0.0));
    let options = TileOptions::new(decimation)
        .with_tile_size(job.tile_size)
        .with_threads(job.threads.map_or(0, |n| n as usize))
        .with_variable_errors(crate::variables::tiled_variable_errors(
            &job.input,
            &variables,
            &largest,
            welded_format.is_some_and(MeshFormat::is_float32),
        )?);
    let placement = Placement::new(info.transform(), job.pixel_coords);
    let crs = if job.pixel_coords {
        None
    } else {
        info.crs_wkt.as_deref()
    };
    let mut progress = |p: TileProgress| feedback.tiles_done(p.done as u64, p.total as u64);
    // What every arm does with the engine's report: no triangle at all is an error, and
    // what is left is writing.
    let meshed = |report: TilesReport| -> Result<TilesReport> {
        if report.final_triangles == 0 {
            bail!(
                "{input}: band {} has no 2x2 block of valid samples, so there is nothing to \
                 triangulate",
                job.band
            );
        }
        feedback.tiles_label("writing");
        Ok(report)
    };

    let (report, output, write_seconds) = match (&job.output, welded_format, &job.per_tile) {
        (Some(output), Some(format), _)
            if !streams(format) || (!variables.is_empty() && format != MeshFormat::Ply) =>
        {
            let mut collector = MeshCollector::new();
            let report = meshed(
                mesh_tiles(&source, &options, &mut collector, &mut progress)
                    .naming_file(&job.input)?,
            )?;
            let t = Instant::now();
            let at_vertices = collector.take_variables();
            let (vertices, triangles) = collector.into_parts();
            let (vertices, triangles) = placement.file_mesh(
                vertices.iter().map(|&[x, y, z]| (x as u32, y as u32, z)),
                triangles,
            );
            let plan = export_plan.expect("planned for -o");
            let attributes: Vec<tinsmith_formats::VertexAttribute<'_>> = variables
                .iter()
                .zip(&at_vertices)
                .map(|((_, name), values)| tinsmith_formats::VertexAttribute { name, values })
                .collect();
            crate::format_plan::write(
                &plan,
                job,
                &info,
                (vertices, &triangles),
                (&attributes, None),
                feedback,
            )?;
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, output.as_path(), write)
        }
        (Some(output), Some(format), _) => {
            let names = variables.iter().map(|(_, name)| name.clone()).collect();
            let mut writer =
                WeldedWriter::create(output, format, crs, placement)?.with_variable_names(names)?;
            let report = meshed(
                mesh_tiles(&source, &options, &mut writer, &mut progress)
                    .naming_file(&job.input)?,
            )?;
            let t = Instant::now();
            writer.finish()?;
            let crs_written = crs.is_some_and(|w| !w.trim().is_empty());
            crate::output_paths::note_prj_left_beside(output, format, crs_written, feedback);
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, output.as_path(), write)
        }
        (_, _, Some(dir)) => {
            let format = match job.tile_format.unwrap_or(TileFormat::Ply) {
                TileFormat::Ply => MeshFormat::Ply,
                TileFormat::Obj => MeshFormat::Obj,
            };
            let names = variables.iter().map(|(_, name)| name.clone()).collect();
            let mut writer =
                PerTileWriter::create(dir, format, crs, placement)?.with_variable_names(names);
            let report = meshed(
                mesh_tiles(&source, &options, &mut writer, &mut progress)
                    .naming_file(&job.input)?,
            )?;
            let t = Instant::now();
            writer.finish()?;
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, dir.as_path(), write)
        }
        _ => bail!("{input}: give -o OUT or --per-tile DIR"),
    };
    feedback.tiles_end();

    let wall = WallSeconds {
        scan: scan_seconds,
        write: write_seconds,
        total: total.elapsed().as_secs_f64(),
    };
    let mut json = tiled_report(
        job,
        output,
        &info,
        &report,
        export_plan,
        vertex_heights_raised,
        wall,
    );
    json.variables = (variables.iter())
        .zip(&report.variables_measured_max_error)
        .map(|((v, name), &measured)| crate::VariableReport::new(v, name, measured))
        .collect();
    json.summary.print(
        &format!(" in {} tiles of {}", json.tiles.count, json.tiles.size),
        feedback,
    );
    for v in &json.variables {
        feedback.note(&format!(
            "{}: band {} ({}) measured max error {} <= {}",
            output.display(),
            v.band,
            v.name,
            tinsmith_georef::readable(v.measured_max_error),
            tinsmith_georef::readable(v.max_error)
        ));
    }
    if let (Some(plan), Some(output)) = (export_plan, &job.output) {
        plan.note_origin(output, feedback);
    }
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&json)?)?;
    }
    tinsmith_output::mark_finished();
    Ok(())
}

/// Wall-clock seconds of a tiled run: the statistics scan, the writing, the whole.
#[derive(Debug, Clone, Copy)]
struct WallSeconds {
    scan: f64,
    write: f64,
    total: f64,
}

/// The `--report` JSON of a tiled run that wrote `output`, from the engine's report `r`.
fn tiled_report<'a>(
    job: &'a MeshJob,
    output: &'a Path,
    info: &tinsmith_raster::RasterInfo,
    r: &TilesReport,
    export_plan: Option<crate::FormatPlan>,
    vertex_heights_raised: bool,
    wall: WallSeconds,
) -> TiledMeshReport<'a> {
    let outcome = Outcome {
        size: (info.width, info.height),
        // With variables, the samples valid in every band.
        valid_samples: match job.variables.is_empty() {
            true => info.valid_samples,
            false => r.valid_samples,
        },
        band_count: info.band_count,
        before: (r.initial_triangles, r.initial_vertices),
        after: (r.final_triangles, r.final_vertices),
        max_error_bound: r.max_bound,
        measured_max_error: r.measured_max_error,
        vertex_heights_raised,
    };
    TiledMeshReport {
        summary: MeshSummary::new(job, output, outcome),
        output_format: export_plan.map(|p| p.report()),
        variables: Vec::new(),
        seconds: Seconds {
            read: wall.scan + r.seconds_read,
            initial_mesh: 0.0,
            decimate: r.seconds_decimation,
            verify: r.seconds_verify,
            write: wall.write,
            total: wall.total,
        },
        tiles: Tiles {
            count: r.plan.len(),
            size: r.plan.size(),
            columns: r.plan.columns(),
            rows: r.plan.rows(),
            threads: r.threads,
            welded: job.per_tile.is_none(),
            scan_seconds: wall.scan,
            tiles_seconds: r.seconds_total,
        },
    }
}

/// Whether the tiled engine streams `format` to the file tile by tile; the other formats
/// are welded in memory (the mesh, not the raster) and written at the end.
fn streams(format: MeshFormat) -> bool {
    matches!(format, MeshFormat::Ply | MeshFormat::Obj)
}
