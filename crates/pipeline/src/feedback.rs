//! What a run tells the person watching it: notes and progress, through a [`Feedback`]
//! the caller supplies (the CLI draws them on stderr; a library caller may drop them).

/// Receives a run's notes and progress. Every method has a default that does nothing, so
/// [`Silent`] is the whole of a caller that wants none of it.
pub trait Feedback {
    /// A note: one or more complete sentences, starting with the file they are about
    /// (summaries, what was left as it was, why a result is smaller than asked).
    fn note(&self, _text: &str) {}
    /// The current progress of a phase, as one line that replaces the previous one.
    fn status(&self, _line: &str) {}
    /// The phase whose progress [`Feedback::status`] showed is over.
    fn clear_status(&self) {}
    /// A count of tiles starts, labelled `label` ("tiles").
    fn tiles_start(&self, _label: &str) {}
    /// `done` of `total` tiles are finished.
    fn tiles_done(&self, _done: u64, _total: u64) {}
    /// The tiles are done and `label` ("writing") is under way.
    fn tiles_label(&self, _label: &str) {}
    /// The count of tiles is over.
    fn tiles_end(&self) {}
}

/// Feedback that shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Feedback for Silent {}
