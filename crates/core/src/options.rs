//! What the caller chooses: the error bound and the paper's strategy knobs.

/// How the error of a candidate triangle is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum ErrorModel {
    /// The paper's §3.3 model: two accumulated bounds per triangle, above and below.
    #[default]
    Bounds,
}

/// Which candidate edge the hole retriangulation picks next (paper §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EdgeSelection {
    /// The edge with the least error bound.
    MinError,
    /// The edge that introduces the least change from the previous triangulation.
    MinIntroduced,
    /// The paper's implementation: `MinIntroduced`, and on a dead end `MinError`.
    #[default]
    Hybrid,
}

/// Options of [`crate::decimate`].
#[derive(Debug, Clone, PartialEq)]
pub struct DecimationOptions {
    /// The promised bound on |sample - TIN| at every domain sample.
    pub max_error: f64,
    /// Candidate-edge selection rule.
    pub selection: EdgeSelection,
    /// Error model.
    pub error_model: ErrorModel,
}

impl DecimationOptions {
    /// Options with the given error bound and the paper's defaults otherwise.
    pub fn new(max_error: f64) -> DecimationOptions {
        DecimationOptions {
            max_error,
            selection: EdgeSelection::default(),
            error_model: ErrorModel::default(),
        }
    }

    /// Sets the edge selection rule.
    pub fn with_selection(mut self, selection: EdgeSelection) -> DecimationOptions {
        self.selection = selection;
        self
    }

    /// Sets the error model.
    pub fn with_error_model(mut self, error_model: ErrorModel) -> DecimationOptions {
        self.error_model = error_model;
        self
    }
}
