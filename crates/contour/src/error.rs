//! The error type of the contouring crate.

/// What can go wrong when building a [`crate::ContourMesh`] or choosing levels; each
/// variant says what the caller should fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {vertex}, but there are only {vertices} vertices")]
    VertexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The vertex index it names.
        vertex: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A triangle uses the same vertex twice.
    #[error("triangle {triangle} uses vertex {vertex} twice")]
    RepeatedVertex {
        /// Index of the triangle.
        triangle: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A vertex used by a triangle has a NaN or infinite coordinate or height.
    #[error("vertex {vertex} has a non-finite coordinate or height")]
    NonFiniteVertex {
        /// The vertex index.
        vertex: u32,
    },
    /// More than two triangles share one edge, so the surface is not a manifold and a
    /// contour through that edge would have no unique continuation.
    #[error("edge ({a}, {b}) is shared by {count} triangles (at most 2 allowed)")]
    NonManifoldEdge {
        /// Smaller vertex of the edge.
        a: u32,
        /// Larger vertex of the edge.
        b: u32,
        /// Number of triangles using it.
        count: usize,
    },
    /// The mesh has more triangles than 32-bit edge handles can address.
    #[error("{triangles} triangles are too many (at most {max})")]
    TooManyTriangles {
        /// Triangles given.
        triangles: usize,
        /// The largest supported count.
        max: usize,
    },
    /// The grid's dimensions and its value count disagree, or it is too large.
    #[error("grid of {width}x{height} needs {expected} values, got {actual} (or is too large)")]
    GridSize {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// width * height.
        expected: usize,
        /// Values supplied.
        actual: usize,
    },
    /// A contour level is NaN or infinite.
    #[error("contour level {} is not a finite number", num(.0))]
    InvalidLevel(f64),
    /// The contour interval is zero, negative, NaN or infinite, or the offset is not finite.
    #[error(
        "contour interval must be a finite number > 0 and the offset finite, got interval {}, \
         offset {}",
        num(.interval),
        num(.offset)
    )]
    InvalidInterval {
        /// The interval given.
        interval: f64,
        /// The offset given.
        offset: f64,
    },
    /// The levels `offset + k * interval` over the heights cannot be told apart in `f64`,
    /// or not placed within a thousandth of the interval of their exact values: the
    /// interval is below the resolution of numbers that large.
    #[error(
        "interval {} with offset {} over heights {}..{}: f64 cannot tell the levels apart \
         or place them evenly at that magnitude; give a larger interval, an offset nearer the \
         heights, or explicit --levels",
        num(.interval),
        num(.offset),
        num(.min),
        num(.max)
    )]
    IntervalBelowResolution {
        /// The interval given.
        interval: f64,
        /// The offset given.
        offset: f64,
        /// Lowest height.
        min: f64,
        /// Highest height.
        max: f64,
    },
    /// The interval is so small for the height range that there would be too many levels.
    #[error(
        "interval {} over heights {}..{} gives {} levels (at most {max_levels})",
        num(.interval),
        num(.min),
        num(.max),
        num(.count)
    )]
    TooManyLevels {
        /// The interval given.
        interval: f64,
        /// Lowest height.
        min: f64,
        /// Highest height.
        max: f64,
        /// Levels it would give.
        count: f64,
        /// The limit, [`crate::MAX_LEVELS`].
        max_levels: usize,
    },
    /// The contour walk met a state a valid mesh cannot produce (a bug, reported instead of
    /// looping or panicking).
    #[error("internal error while joining contour segments at level {level}: {what}")]
    Internal {
        /// The level being joined.
        level: f64,
        /// What went wrong.
        what: &'static str,
    },
}

/// Result of the contouring crate's fallible functions.
pub type Result<T> = std::result::Result<T, Error>;

/// A number as people read it: with an exponent when very large or very small (`1e-300`,
/// not three hundred zeros), as written otherwise.
fn num(x: &f64) -> String {
    let magnitude = x.abs();
    if magnitude != 0.0 && magnitude.is_finite() && !(1e-5..1e16).contains(&magnitude) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}
