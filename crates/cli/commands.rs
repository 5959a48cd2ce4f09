//! Each command: its flags into a job, the pipeline run with feedback on stderr, and
//! what it prints on stdout.

use anyhow::Result;

use crate::args::{ContourArgs, MeshArgs, PreviewArgs, ServeArgs, TilesArgs, TilesStep};
use crate::progress::Stderr;

/// `tinsmith mesh`; `Ok(true)` once the verified mesh is written.
pub fn mesh(args: &MeshArgs) -> Result<bool> {
    tinsmith_pipeline::mesh(&args.job()?, &Stderr::new(args.quiet))?;
    Ok(true)
}

/// `tinsmith contour`; `Ok(true)` once the lines are written.
pub fn contour(args: &ContourArgs) -> Result<bool> {
    tinsmith_pipeline::contour(&args.job(), &Stderr::new(args.quiet))?;
    Ok(true)
}

/// `tinsmith tiles`; `Ok(true)` once the pyramid is in place.
pub fn tiles(args: &TilesArgs) -> Result<bool> {
    if let Some(TilesStep::Merge(merge)) = &args.step {
        let run = &merge.run;
        let feedback = Stderr::new(run.quiet);
        let report = run.report.as_deref();
        tinsmith_pipeline::merge_tiles(&merge.dir, run.threads, report, &feedback)?;
        return Ok(true);
    }
    let (Some(input), Some(output)) = (&args.input, &args.output) else {
        unreachable!("clap requires INPUT and --output without a subcommand");
    };
    let mut options = args.options(tinsmith_pipeline::available_bytes());
    let feedback = Stderr::new(args.run.quiet);
    options.vertical_datum = tinsmith_pipeline::vertical_datum(
        input,
        args.band,
        args.vertical_datum.as_deref(),
        &feedback,
    )?;
    options.water = tinsmith_pipeline::water_source(input, args.band, args.water.as_deref())?;
    if let Some(base) = &args.base {
        let datum = args.vertical_datum.as_deref();
        options.base = Some(tinsmith_pipeline::base_raster(base, datum, &feedback)?);
    }
    let report = args.run.report.as_deref();
    match args.shard {
        Some(shard) => {
            tinsmith_pipeline::tiles_shard(input, output, report, &options, shard, &feedback)?;
        }
        None => {
            tinsmith_pipeline::tiles(input, output, report, &options, &feedback)?;
        }
    }
    Ok(true)
}

/// `tinsmith serve`: announces the address on stdout, then serves.
pub fn serve(args: &ServeArgs) -> Result<bool> {
    use std::io::Write as _;
    let server = tinsmith_pipeline::serve(&args.options(), &Stderr::new(false))?;
    // A closed stdout only loses the announcement; the server still serves.
    let mut stdout = std::io::stdout();
    let _ = writeln!(
        stdout,
        "serving {} at http://{}/",
        args.path.display(),
        server.addr()?
    );
    let _ = stdout.flush();
    server.run(args.max_requests)?;
    Ok(true)
}

/// `tinsmith preview`: draws the picture and says what it shows.
pub fn preview(args: &PreviewArgs) -> Result<bool> {
    let drawn = match (&args.mesh, args.max_error) {
        (Some(_), _) => tinsmith_pipeline::preview(&args.job())?,
        (None, Some(bound)) => {
            let mut decimate = tinsmith_pipeline::MeshJob::new(&args.input);
            decimate.decimation.max_error = Some(bound);
            tinsmith_pipeline::preview_decimated(&args.job(), &decimate, &Stderr::new(true))?
        }
        (None, None) => anyhow::bail!(
            "{}: give the MESH to draw, or --max-error to decimate the raster first",
            args.input.display()
        ),
    };
    let scale = drawn
        .error_scale
        .map(|e| format!("; error colours span +/-{}", tinsmith_pipeline::readable(e)))
        .unwrap_or_default();
    let checked = match drawn.verified_max_error {
        Some(e) => format!("max error {}", tinsmith_pipeline::readable(e)),
        None => format!(
            "max error at the drawn samples {}; the raster is larger than a preview reads \
             whole, so the mesh was not verified at every sample",
            tinsmith_pipeline::readable(drawn.max_error)
        ),
    };
    eprintln!(
        "wrote {} ({} x {} pixels, {} samples per pixel; {} vertices, {} triangles, \
         {checked}{scale})",
        args.output.display(),
        drawn.width,
        drawn.height,
        tinsmith_pipeline::readable(drawn.samples_per_pixel),
        drawn.vertices,
        drawn.triangles,
    );
    Ok(true)
}
