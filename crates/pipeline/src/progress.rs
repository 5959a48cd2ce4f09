//! A one-line progress display on stderr, shown only when stderr is a terminal.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// Rewrites one stderr line at most five times a second; silent when quiet or when stderr
/// is not a terminal (pipes and CI logs stay clean).
pub struct Progress {
    enabled: bool,
    last: Option<Instant>,
    shown: bool,
}

impl Progress {
    pub fn new(quiet: bool) -> Progress {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
            last: None,
            shown: false,
        }
    }

    pub fn show(&mut self, line: &str) {
        if !self.enabled
            || self
                .last
                .is_some_and(|t| t.elapsed() < Duration::from_millis(200))
        {
            return;
        }
        self.last = Some(Instant::now());
        self.shown = true;
        let _ = write!(std::io::stderr(), "\r\x1b[2K{line}");
    }

    pub fn clear(&mut self) {
        if self.shown {
            let _ = write!(std::io::stderr(), "\r\x1b[2K");
            self.shown = false;
        }
    }
}

/// Scans band `band` of `input` for its statistics ([`tinsmith_raster::open_info`]: a full
/// read, long on a large raster), showing the share of rows done unless `quiet`.
pub fn scan_raster(
    input: &std::path::Path,
    band: usize,
    quiet: bool,
) -> tinsmith_raster::Result<tinsmith_raster::RasterInfo> {
    let mut progress = Progress::new(quiet);
    let name = input.display();
    let info = tinsmith_raster::open_info_with_progress(input, band, &mut |done, rows| {
        progress.show(&format!(
            "{name}: scanning, {} % of the rows",
            done * 100 / rows.max(1)
        ));
    });
    progress.clear();
    info
}
