//! What can go wrong storing a pyramid.

/// A store's failure, naming the destination.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// Reading or writing failed.
    #[error("{location}: {source}")]
    Io {
        /// The file, object or container.
        location: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A named file's name is not a plain relative name.
    #[error("{name:?} is not a plain relative file name")]
    BadName {
        /// The name given.
        name: String,
    },
    /// The destination cannot be used (wrong kind, unreachable, refused).
    #[error("{location}: {reason}")]
    Unusable {
        /// The destination.
        location: String,
        /// Why.
        reason: String,
    },
}

/// A result with [`StoreError`].
pub type StoreResult<T> = Result<T, StoreError>;
