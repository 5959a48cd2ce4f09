//! `tinsmith`: error-bounded DEM to TIN conversion on the command line.
//!
//! Exit codes: 0 success; 1 `verify` measured the mesh and found it outside the bound or
//! invalid; 2 bad input or any other error (the message names the file and the problem).

/// `eprintln!` for notes (summaries, warnings, the final error): a closed stderr (`2>&1 |
/// head`) is not an error, and must not panic in the middle of writing output files.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod args;
mod commands;
mod info;
mod progress;
mod verify;

use std::process::ExitCode;

use clap::Parser;

use crate::args::{Cli, Command};

/// Exit code when verification fails.
const EXIT_VERIFY_FAILED: u8 = 1;
/// Exit code for bad input and other errors.
const EXIT_ERROR: u8 = 2;
/// Exit code when the output was a pipe whose reader closed it early: 128 + SIGPIPE, what
/// a shell reports for a process the signal ended.
const EXIT_BROKEN_PIPE: u8 = 141;
/// Exit codes after a signal are 128 + its number, as shells report a process the signal
/// ended: 130 after Ctrl-C (SIGINT), 143 after SIGTERM, 129 after SIGHUP.
const EXIT_SIGNALLED: i32 = 128;

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Ctrl-C, SIGTERM or SIGHUP: no half-written temporary file or directory may stay
    // behind (their owners' drops, which remove them on errors, do not run on a signal's
    // exit). The signals are taken on a thread of their own, where files can be removed.
    on_signal_remove_pending_output();
    // Errors come back as values with GDAL's message; GDAL need not print them too, and
    // its warnings wait for the end of the run.
    tinsmith_raster::silence_gdal_errors();
    if matches!(cli.command, Command::Info(_) | Command::Verify(_)) {
        end_quietly_on_closed_stdout();
    }
    // Every command reads each block of a raster once per open dataset (a scan, a
    // whole-raster read, tiles in order, a pyramid's plan at a coarse size): GDAL's default
    // cache, 5 % of the machine's memory, would only hold blocks never read again (`info`
    // on a 40k x 40k raster peaked at 1.16 GB; a pyramid shard's plan of a 537 MB raster
    // at 577 MB).
    tinsmith_raster::limit_block_cache(BLOCK_CACHE_MB);
    let quiet = match &cli.command {
        Command::Mesh(a) => a.quiet,
        Command::Contour(a) => a.quiet,
        Command::Tiles(a) => a.run.quiet,
        Command::Info(_) | Command::Verify(_) | Command::Serve(_) | Command::Preview(_) => true,
    };
    let result = match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Mesh(a) => commands::mesh(&a),
        Command::Verify(a) => verify::run(&a),
        Command::Contour(a) => commands::contour(&a),
        Command::Tiles(a) => commands::tiles(&a),
        Command::Serve(a) => commands::serve(&a),
        Command::Preview(a) => commands::preview(&a),
    };
    if tinsmith_output::interrupted() {
        // The signal handler is removing the unfinished output (the error, if any, comes
        // from that) and exits the process itself.
        loop {
            std::thread::park();
        }
    }
    note_removed_stale(quiet);
    // GDAL's warnings only on success: a failure is one line naming the file and the
    // problem, which warnings about the same malformed file would bury.
    let warnings = tinsmith_raster::take_gdal_warnings();
    if result.is_ok() {
        for warning in warnings {
            note!("GDAL warning: {warning}");
        }
    }
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(EXIT_VERIFY_FAILED),
        Err(err) => {
            if is_broken_pipe(&err) {
                // The reader of a pipe stopped early: quiet, but not a success (a shell
                // reports a process killed by SIGPIPE so, and `set -o pipefail` sees it).
                return ExitCode::from(EXIT_BROKEN_PIPE);
            }
            note!("tinsmith: {}", one_line(&err));
            ExitCode::from(EXIT_ERROR)
        }
    }
}

/// Notes (unless `quiet`) the temporary outputs of killed runs that writing this run's
/// outputs removed (see `tinsmith_output::take_removed_stale`).
fn note_removed_stale(quiet: bool) {
    let removed = tinsmith_output::take_removed_stale();
    if quiet || removed.is_empty() {
        return;
    }
    let bytes: u64 = removed.iter().map(|r| r.bytes).sum();
    let shown: Vec<String> = removed
        .iter()
        .take(3)
        .map(|r| r.path.display().to_string())
        .collect();
    let more = match removed.len() {
        n if n > 3 => format!(" and {} more", n - 3),
        _ => String::new(),
    };
    let partly = match removed.iter().filter(|r| !r.complete).count() {
        0 => String::new(),
        n => format!(" ({n} only in part: some files in them could not be removed)"),
    };
    let size = match bytes {
        b if b >= 1_000_000_000 => format!("{:.1} GB", b as f64 / 1e9),
        b if b >= 1_000_000 => format!("{:.1} MB", b as f64 / 1e6),
        b if b >= 1_000 => format!("{:.1} kB", b as f64 / 1e3),
        b => format!("{b} bytes"),
    };
    note!(
        "tinsmith: note: removed {} temporary output(s) that killed runs left behind \
         ({size}): {}{more}{partly}",
        removed.len(),
        shown.join(", ")
    );
}

/// GDAL block cache, in MB, for every command (each reads a block once per open dataset):
/// several rows of tiles of a 16k-wide Float32 raster, whether in strips or blocks.
const BLOCK_CACHE_MB: u64 = 256;

/// `info` and `verify` print their results on stdout and write no file: like other Unix
/// tools they end quietly when the reader of a pipe goes away (`| head`), where Rust's
/// ignored SIGPIPE would make `println!` panic.
fn end_quietly_on_closed_stdout() {
    // SAFETY: restoring the default action of a signal; no handler code is involved.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The error and its causes on one line, skipping a cause already quoted by the message
/// above it, and the gdal crate's wrapper texts (the raster errors quote GDAL's reason).
fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        let gdal_wrapper = text.starts_with("GDAL method")
            || (text.starts_with("CPL error class") && !line.is_empty());
        if !line.contains(&text) && !gdal_wrapper {
            if !line.is_empty() {
                line.push_str(": ");
            }
            line.push_str(&text);
        }
    }
    line.replace('\n', " ")
}

/// Whether a write to a closed pipe caused `err`, also where a library wrapped the
/// `io::Error` inside another (FlatGeobuf's writer does).
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    fn broken(e: &(dyn std::error::Error + 'static)) -> bool {
        let Some(io) = e.downcast_ref::<std::io::Error>() else {
            return false;
        };
        io.kind() == std::io::ErrorKind::BrokenPipe
            || io
                .get_ref()
                .is_some_and(|inner| broken(inner) || inner.source().is_some_and(broken))
    }
    err.chain().any(broken)
}

/// Starts the thread that, on SIGINT, SIGTERM or SIGHUP, applies `tinsmith_output`'s one
/// rule (see `tinsmith_output::on_signal`): before the run's first output is in place it
/// removes the unfinished output and exits with 128 + the signal's number, every old
/// output left as it was; after, it lets the run put the rest in place and exit 0 (a
/// second signal while it does ends the process at once). If the handlers cannot be
/// registered, the signals keep their default action (the process ends at once, leaving
/// its temporary files).
fn on_signal_remove_pending_output() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    // A thread that cannot start (at the first lines of `main`, only short of memory)
    // takes the registration with it when the closure is dropped.
    let started = std::thread::Builder::new()
        .name("tinsmith-signals".to_owned())
        .spawn(move || {
            let Some(signal) = signals.forever().next() else {
                return;
            };
            match tinsmith_output::on_signal() {
                tinsmith_output::Interrupt::Completing => {
                    if !tinsmith_output::finished() {
                        note!(
                            "\ntinsmith: signal received while the outputs were being put in \
                             place; finishing them (signal again to stop at once)"
                        );
                    }
                    // The rest is renames and a report: moments. `main` may also end first,
                    // with the run's own exit code.
                    while !tinsmith_output::finished() {
                        if let Some(again) = signals.pending().next() {
                            // SAFETY: as below.
                            unsafe { libc::_exit(EXIT_SIGNALLED + again) }
                        }
                        std::thread::sleep(std::time::Duration::from_millis(10));
                    }
                    // Every output is complete and in place; only memory is being freed.
                    // SAFETY: as below.
                    unsafe { libc::_exit(0) }
                }
                tinsmith_output::Interrupt::Cancelled { removed } => {
                    if removed > 0 {
                        note!("\ntinsmith: interrupted; unfinished output removed");
                    } else {
                        note!("\ntinsmith: interrupted");
                    }
                }
            }
            // SAFETY: `_exit` takes no pointers and never returns. Unlike `process::exit`
            // it runs no atexit handlers, which would tear GDAL's global state down under
            // the worker threads still reading (a segfault, seen in tests).
            unsafe { libc::_exit(EXIT_SIGNALLED + signal) }
        });
    drop(started);
}
