//! `tinsmith verify`: measure a mesh file's true error against its raster.

use anyhow::Result;
use tinsmith_pipeline::readable;
use tinsmith_verify::Report;

use crate::args::VerifyArgs;

/// Runs the verifier and prints its report; `Ok(false)` when the mesh is invalid or
/// exceeds `--max-error`.
pub fn run(args: &VerifyArgs) -> Result<bool> {
    if tinsmith_pipeline::is_point_input(&args.input)
        || args.points.breaklines.is_some()
        || args.points.boundary.is_some()
    {
        let [max_error] = args.max_error[..] else {
            anyhow::bail!(
                "{}: verifying points needs one --max-error",
                args.input.display()
            );
        };
        let report = tinsmith_pipeline::verify_points_file(
            &args.input,
            &args.mesh,
            args.format,
            max_error,
            &args.points.choices(None),
            args.band,
            &tinsmith_pipeline::Silent,
        )?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            println!("{}", tinsmith_pipeline::points_summary(&report));
        }
        return Ok(report.passed());
    }
    let verified = tinsmith_pipeline::verify(&args.job()?)?;
    let report = &verified.report;
    if args.json && verified.variables.is_empty() {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else if args.json {
        let variables: Vec<_> = verified
            .variables
            .iter()
            .map(|(v, r)| serde_json::json!({ "variable": v, "report": r }))
            .collect();
        let both = serde_json::json!({ "height": report, "variables": variables });
        println!("{}", serde_json::to_string_pretty(&both)?);
    } else {
        print_report(report, args);
        for (v, r) in &verified.variables {
            println!(
                "band {} ({}):{}max error {}, allowed {}{}",
                v.band,
                v.name,
                " ".repeat(
                    9usize
                        .saturating_sub(v.band.to_string().len() + v.name.len())
                        .max(1)
                ),
                readable(v.measured_max_error),
                readable(v.max_error),
                if r.passed() { "" } else { "  FAILED" }
            );
            for problem in &r.problems {
                println!("  problem:       {problem}");
            }
        }
    }
    if !report.passed() && verified.band_count > 1 {
        note!(
            "{}: note: verified against band {} of {}; a mesh of another band fails here \
             (--band picks another)",
            args.mesh.display(),
            args.band,
            verified.band_count
        );
    }
    Ok(verified.passed())
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
