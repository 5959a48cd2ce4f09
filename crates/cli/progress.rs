//! The pipeline's feedback on stderr: notes, a one-line progress display and a tile
//! bar, the last two shown only when stderr is a terminal.

use std::cell::RefCell;
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use tinsmith_pipeline::Feedback;

/// Rewrites one stderr line at most five times a second; silent when quiet or when stderr
/// is not a terminal (pipes and CI logs stay clean).
struct Progress {
    enabled: bool,
    last: Option<Instant>,
    shown: bool,
}

impl Progress {
    fn new(quiet: bool) -> Progress {
        Progress {
            enabled: !quiet && std::io::stderr().is_terminal(),
            last: None,
            shown: false,
        }
    }

    fn show(&mut self, line: &str) {
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

    fn clear(&mut self) {
        if self.shown {
            let _ = write!(std::io::stderr(), "\r\x1b[2K");
            self.shown = false;
        }
    }
}

/// The pipeline's notes and progress on stderr: notes unless quiet; the progress line and
/// the tile bar only on a terminal.
pub struct Stderr {
    quiet: bool,
    line: RefCell<Progress>,
    bar: RefCell<Option<ProgressBar>>,
}

impl Stderr {
    /// Feedback for a run with `--quiet` as `quiet`.
    pub fn new(quiet: bool) -> Stderr {
        Stderr {
            quiet,
            line: RefCell::new(Progress::new(quiet)),
            bar: RefCell::new(None),
        }
    }
}

impl Feedback for Stderr {
    fn note(&self, text: &str) {
        if !self.quiet {
            note!("{text}");
        }
    }

    fn status(&self, line: &str) {
        self.line.borrow_mut().show(line);
    }

    fn clear_status(&self) {
        self.line.borrow_mut().clear();
    }

    fn tiles_start(&self, label: &str) {
        let bar = tile_bar(self.quiet);
        bar.set_message(label.to_owned());
        bar.reset_eta();
        *self.bar.borrow_mut() = Some(bar);
    }

    fn tiles_done(&self, done: u64, total: u64) {
        if let Some(bar) = &*self.bar.borrow() {
            bar.set_length(total);
            bar.set_position(done);
        }
    }

    fn tiles_label(&self, label: &str) {
        if let Some(bar) = &*self.bar.borrow() {
            bar.set_message(label.to_owned());
        }
    }

    fn tiles_end(&self) {
        if let Some(bar) = self.bar.borrow_mut().take() {
            bar.finish_and_clear();
        }
    }
}

/// Tiles done / total with the ETA on stderr; hidden when quiet or when stderr is not a
/// terminal.
fn tile_bar(quiet: bool) -> ProgressBar {
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
