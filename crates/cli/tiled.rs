//! `tinsmith mesh` on rasters larger than one tile (or with `--per-tile`): the tiled
//! engine of `tinsmith-tile`, with a progress bar and the same report as the untiled path
//! plus the tile fields.

use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use tinsmith_export::MeshFormat;
use tinsmith_tile::{
    mesh_tiles, MeshCollector, PerTileWriter, Placement, RasterSource, TileOptions, TilePlan,
    TileProgress, TilesReport, WeldedWriter,
};

use crate::args::{MeshArgs, TileFormatArg};
use crate::output::NamingFile;
use crate::report::{MeshSummary, Outcome, Seconds};

/// The output file when the untiled engine should run: no `--per-tile`, and the raster
/// fits in one tile or a triangle or vertex count is the target (which needs the whole
/// raster at once). `None` when the tiled engine should run.
pub fn untiled_output(args: &MeshArgs) -> Result<Option<&Path>> {
    let Some(output) = args.output.as_deref() else {
        return Ok(None);
    };
    if args.per_tile.is_some() {
        return Ok(None);
    }
    // Checks the untiled path makes first, so that errors come in the same order.
    let format = crate::export::format(args)?;
    crate::output::check_writable_target(output, &args.input)?;
    let reader = tinsmith_raster::WindowReader::open(&args.input, args.band)?;
    if !args.pixel_coords {
        // The CRS written: none for a raster without a geotransform (pixel coordinates).
        let info = reader.info();
        let crs_wkt = info
            .crs_wkt
            .as_deref()
            .filter(|_| info.transform().is_some());
        crate::output::check_sidecar(output, &args.input, format, crs_wkt)?;
    }
    crate::transform_check::check_transform(reader.info(), args.pixel_coords)?;
    crate::export::check_float32_positions(format, reader.info(), args)?;
    let fits = reader.width() <= args.tile_size && reader.height() <= args.tile_size;
    let count_target = args.max_triangles.is_some() || args.max_vertices.is_some();
    if count_target && !fits {
        // The start mesh has four times the triangles asked for, at most two per sample.
        let by_vertices = args
            .max_vertices
            .map_or(u64::MAX, |v| (v as u64).saturating_mul(2));
        let target = (args.max_triangles.map_or(u64::MAX, |t| t as u64)).min(by_vertices);
        let samples = u64::from(reader.width()) * u64::from(reader.height());
        let start_triangles = target.saturating_mul(4).min(samples.saturating_mul(2));
        crate::memory::check_whole_raster_fits(
            &args.input,
            (reader.width(), reader.height()),
            crate::memory::Need {
                bytes_per_sample: 50,
                extra_bytes: start_triangles
                    .saturating_mul(crate::memory::BYTES_PER_START_TRIANGLE),
            },
            "a --max-triangles or --max-vertices target",
            "give --max-error instead (decimated tile by tile, in bounded memory)",
        )?;
    } else if fits {
        // 82 bytes per sample measured untiled on ETOPO5 at ε = 1 (session 2), more at
        // smaller bounds.
        crate::memory::check_whole_raster_fits(
            &args.input,
            (reader.width(), reader.height()),
            crate::memory::Need {
                bytes_per_sample: 120,
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
    output_format: Option<crate::export::PlanReport>,
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
pub fn run(args: &MeshArgs) -> Result<bool> {
    let total = Instant::now();
    let input = args.input.display();
    if args.max_triangles.is_some() || args.max_vertices.is_some() {
        bail!(
            "{input}: --max-triangles and --max-vertices need the whole raster at once, and \
             --per-tile meshes it tile by tile; give --max-error"
        );
    }
    let Some(max_error) = args.max_error else {
        bail!("{input}: tiles need --max-error");
    };
    // With -o, `untiled_output` has checked the output path, its sidecar and the
    // geotransform; --per-tile has not been through it.
    let welded_format = match &args.output {
        Some(_) => Some(crate::export::format(args)?),
        None => {
            crate::transform_check::check_input_transform(
                &args.input,
                args.band,
                args.pixel_coords,
            )?;
            None
        }
    };
    let welded_output = args.output.as_deref().zip(welded_format);
    let reserved = crate::mesh::reserve_report(args, welded_output)?;

    let t = Instant::now();
    let info = crate::progress::scan_raster(&args.input, args.band, args.quiet)?;
    crate::output::note_gcps_unused(&info, args.pixel_coords, args.quiet);
    let source = RasterSource::new(&info)?;
    let scan_seconds = t.elapsed().as_secs_f64();
    let bar = progress_bar(args.quiet);
    let plan = TilePlan::new(info.width, info.height, args.tile_size).naming_file(&args.input)?;
    bar.set_length(plan.len() as u64);
    bar.set_message("tiles");
    bar.reset_eta();

    // Float32 formats leave the decimator the bound less their height rounding.
    let export_plan = match welded_format {
        Some(format) => Some(crate::export::Plan::new(format, &info, None, args)?),
        None => None,
    };
    let bound = export_plan.map_or(max_error, |p| p.decimation_bound);
    let heights = info.min.zip(info.max);
    crate::report::note_rounding_margin(&args.input, bound, heights, args.quiet);
    let decimation = args
        .decimation_options(bound, heights)
        .naming_file(&args.input)?;
    let vertex_heights_raised =
        decimation.raises_vertex_heights(info.max_abs_value().unwrap_or(0.0));
    let options = TileOptions::new(decimation)
        .with_tile_size(args.tile_size)
        .with_threads(args.threads.map_or(0, |n| n as usize));
    let placement = Placement::new(info.transform(), args.pixel_coords);
    let crs = if args.pixel_coords {
        None
    } else {
        info.crs_wkt.as_deref()
    };
    let mut progress = |p: TileProgress| bar.set_position(p.done as u64);
    // What every arm does with the engine's report: no triangle at all is an error, and
    // what is left is writing.
    let meshed = |report: TilesReport| -> Result<TilesReport> {
        if report.final_triangles == 0 {
            bail!(
                "{input}: band {} has no 2x2 block of valid samples, so there is nothing to \
                 triangulate",
                args.band
            );
        }
        bar.set_message("writing");
        Ok(report)
    };

    let (report, output, write_seconds) = match (&args.output, welded_format, &args.per_tile) {
        (Some(output), Some(format), _) if !streams(format) => {
            let mut collector = MeshCollector::new();
            let report = meshed(
                mesh_tiles(&source, &options, &mut collector, &mut progress)
                    .naming_file(&args.input)?,
            )?;
            let t = Instant::now();
            let (vertices, triangles) = collector.into_parts();
            let georef = Placement::new(info.transform(), args.pixel_coords);
            let (vertices, triangles) = georef.file_mesh(
                vertices.iter().map(|&[x, y, z]| (x as u32, y as u32, z)),
                triangles,
            );
            let plan = export_plan.expect("planned for -o");
            crate::export::write(&plan, args, &info, vertices, &triangles)?;
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, output.as_path(), write)
        }
        (Some(output), Some(format), _) => {
            let mut writer = WeldedWriter::create(output, format, crs, placement)?;
            let report = meshed(
                mesh_tiles(&source, &options, &mut writer, &mut progress)
                    .naming_file(&args.input)?,
            )?;
            let t = Instant::now();
            writer.finish()?;
            let crs_written = crs.is_some_and(|w| !w.trim().is_empty());
            crate::output::note_prj_left_beside(output, format, crs_written, args.quiet);
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, output.as_path(), write)
        }
        (_, _, Some(dir)) => {
            let format = match args.tile_format.unwrap_or(TileFormatArg::Ply) {
                TileFormatArg::Ply => MeshFormat::Ply,
                TileFormatArg::Obj => MeshFormat::Obj,
            };
            let mut writer = PerTileWriter::create(dir, format, crs, placement)?;
            let report = meshed(
                mesh_tiles(&source, &options, &mut writer, &mut progress)
                    .naming_file(&args.input)?,
            )?;
            let t = Instant::now();
            writer.finish()?;
            let write = report.seconds_sink + t.elapsed().as_secs_f64();
            (report, dir.as_path(), write)
        }
        _ => bail!("{input}: give -o OUT or --per-tile DIR"),
    };
    bar.finish_and_clear();

    let r: &TilesReport = &report;
    let outcome = Outcome {
        size: (info.width, info.height),
        valid_samples: info.valid_samples,
        band_count: info.band_count,
        before: (r.initial_triangles, r.initial_vertices),
        after: (r.final_triangles, r.final_vertices),
        max_error_bound: r.max_bound,
        measured_max_error: r.measured_max_error,
        vertex_heights_raised,
    };
    let json = TiledMeshReport {
        summary: MeshSummary::new(args, output, outcome),
        output_format: export_plan.map(|p| p.report()),
        seconds: Seconds {
            read: scan_seconds + r.seconds_read,
            initial_mesh: 0.0,
            decimate: r.seconds_decimation,
            verify: r.seconds_verify,
            write: write_seconds,
            total: total.elapsed().as_secs_f64(),
        },
        tiles: Tiles {
            count: r.plan.len(),
            size: r.plan.size(),
            columns: r.plan.columns(),
            rows: r.plan.rows(),
            threads: r.threads,
            welded: args.per_tile.is_none(),
            scan_seconds,
            tiles_seconds: r.seconds_total,
        },
    };
    if !args.quiet {
        json.summary.print(&format!(
            " in {} tiles of {}",
            json.tiles.count, json.tiles.size
        ));
        if let (Some(plan), Some(output)) = (export_plan, &args.output) {
            plan.note_origin(output);
        }
    }
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&json)?)?;
    }
    tinsmith_export::mark_finished();
    Ok(true)
}

/// Whether the tiled engine streams `format` to the file tile by tile; the other formats
/// are welded in memory (the mesh, not the raster) and written at the end.
fn streams(format: MeshFormat) -> bool {
    matches!(format, MeshFormat::Ply | MeshFormat::Obj)
}

/// Tiles done / total with the ETA on stderr; hidden when quiet or when stderr is not a
/// terminal.
pub fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(0);
    if let Ok(style) = ProgressStyle::with_template(
        "{msg:>8} [{bar:32}] {pos}/{len} tiles, {elapsed_precise} elapsed, ETA {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}
