//! The pipeline's feedback on stderr: notes unless `--quiet`, and progress (a status line
//! or a tile bar, drawn by indicatif) only when stderr is a terminal, so pipes and CI
//! logs stay clean.

use std::cell::RefCell;
use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use tinsmith_pipeline::Feedback;

/// Notes and progress of one run on stderr.
pub struct Stderr {
    quiet: bool,
    /// The status line or the tile bar being drawn.
    bar: RefCell<Option<ProgressBar>>,
}

impl Stderr {
    /// Feedback for a run with `--quiet` as `quiet`.
    pub fn new(quiet: bool) -> Stderr {
        Stderr {
            quiet,
            bar: RefCell::new(None),
        }
    }

    /// A bar drawn with `template`; hidden when quiet or when stderr is not a terminal.
    fn start(&self, template: &str) -> ProgressBar {
        if self.quiet || !std::io::stderr().is_terminal() {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::new(0);
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    }

    fn end(&self) {
        if let Some(bar) = self.bar.borrow_mut().take() {
            bar.finish_and_clear();
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
        let mut bar = self.bar.borrow_mut();
        bar.get_or_insert_with(|| self.start("{msg}"))
            .set_message(line.to_owned());
    }

    fn clear_status(&self) {
        self.end();
    }

    fn tiles_start(&self, label: &str) {
        self.end();
        let bar = self
            .start("{msg:>8} [{bar:32}] {pos}/{len} tiles, {elapsed_precise} elapsed, ETA {eta}");
        bar.set_message(label.to_owned());
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
        self.end();
    }
}
