//! `tinsmith tiles`: a quantized-mesh terrain pyramid.

use anyhow::Result;
use tinsmith_tile::{build_terrain, TerrainOptions};

use crate::args::TilesArgs;
use crate::output::NamingFile;

pub fn run(args: &TilesArgs) -> Result<bool> {
    let options = TerrainOptions {
        band: args.band,
        min_zoom: args.min_zoom,
        max_zoom: args.max_zoom,
        quality: args.quality,
        normals: args.normals,
        metadata: args.metadata,
        gzip: !args.no_gzip,
        threads: args.threads,
        memory_limit: crate::memory::available_bytes(),
    };
    if let Some(report) = &args.report {
        crate::output::check_not_inside(&args.output, report, "the pyramid directory")?;
        crate::output::check_writable_target(report, &args.input)?;
    }
    let reserved = args
        .report
        .as_deref()
        .map(crate::output::ReservedReport::reserve)
        .transpose()?;
    let report = build_terrain(&args.input, &args.output, &options, &mut |level| {
        if args.quiet {
            return;
        }
        let flat = match level.flat_tiles {
            0 => String::new(),
            n => format!(" ({n} flat: a root tile without data, for --metadata)"),
        };
        note!(
            "level {:>2}: {} tiles{flat}, {} bytes, bound {:.3} m, measured {:.3} m, {:.2} s",
            level.level,
            level.tiles,
            level.bytes,
            level.achieved_bound,
            level.measured_max_error,
            level.seconds
        );
    })
    .naming_file(&args.input)?;
    if let Some(reserved) = reserved {
        reserved.write(&serde_json::to_vec_pretty(&report)?)?;
    }
    tinsmith_output::mark_finished();
    if args.quiet {
        return Ok(true);
    }
    let tiles: u64 = report.levels.iter().map(|l| l.tiles).sum();
    note!(
        "{tiles} tiles, levels {}..={}, in {}{}",
        report.min_zoom,
        report.max_zoom,
        args.output.display(),
        if args.no_gzip {
            ""
        } else {
            " (gzipped: serve with Content-Encoding: gzip, e.g. `tinsmith serve`)"
        }
    );
    Ok(true)
}
