//! The error type of the verifier: only inconsistent input lengths are errors.

/// Inputs whose lengths disagree, so nothing can be checked.
///
/// Everything else that can be wrong with a mesh (bad vertices, flipped triangles, holes,
/// large error) is not an error but a finding, recorded in the [`Report`](crate::Report).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum VerifyError {
    /// The grid's value count is not `width * height`.
    #[error("grid of {width}x{height} needs {expected} values, got {actual}")]
    GridSize {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// `width * height`.
        expected: u64,
        /// Values supplied.
        actual: usize,
    },
    /// The mesh has a different number of heights than vertex positions.
    #[error("mesh has {positions} vertex positions but {heights} heights")]
    MeshSize {
        /// Vertex positions supplied.
        positions: usize,
        /// Heights supplied.
        heights: usize,
    },
    /// Samples picked along one side of the grid are not strictly increasing inside it.
    #[error("the picked {what} must be strictly increasing and below {side}")]
    Lattice {
        /// `columns` or `rows`.
        what: &'static str,
        /// The grid's samples along that side.
        side: u32,
    },
}

/// Result of the verifier's fallible functions.
pub type Result<T> = std::result::Result<T, VerifyError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_numbers() {
        let e = VerifyError::GridSize {
            width: 3,
            height: 2,
            expected: 6,
            actual: 5,
        };
        assert_eq!(e.to_string(), "grid of 3x2 needs 6 values, got 5");
        let e = VerifyError::MeshSize {
            positions: 4,
            heights: 3,
        };
        assert_eq!(e.to_string(), "mesh has 4 vertex positions but 3 heights");
    }
}
