//! The human-readable problem list: the first few findings of each kind, then a count.

use std::fmt;

/// How many lines of each kind are kept; the rest are only counted.
pub(crate) const LINES_PER_KIND: usize = 5;

/// The kinds of finding, in the order their overflow counts are listed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A triangle corner indexes past the vertex list.
    BadIndex,
    /// A vertex position is outside the grid.
    VertexOutsideGrid,
    /// A vertex position is on a nodata sample.
    VertexOnNodata,
    /// A vertex height is NaN or infinite.
    NonFiniteHeight,
    /// A triangle could not be measured because of a bad vertex.
    Unmeasured,
    /// A triangle has zero area.
    Degenerate,
    /// A triangle has the wrong winding.
    Flipped,
    /// A triangle covers a nodata sample.
    NodataCovered,
    /// A domain sample is covered by no triangle.
    Uncovered,
    /// The mesh area differs from the domain area.
    AreaMismatch,
    /// An edge inside the domain borders one triangle only.
    OpenEdge,
    /// An edge is shared by triangles on the same side, or by more than two.
    OverlappingEdge,
    /// The maximum error exceeds the allowed one.
    ErrorExceeded,
}

impl Kind {
    const ALL: [Kind; 13] = [
        Kind::BadIndex,
        Kind::VertexOutsideGrid,
        Kind::VertexOnNodata,
        Kind::NonFiniteHeight,
        Kind::Unmeasured,
        Kind::Degenerate,
        Kind::Flipped,
        Kind::NodataCovered,
        Kind::Uncovered,
        Kind::AreaMismatch,
        Kind::OpenEdge,
        Kind::OverlappingEdge,
        Kind::ErrorExceeded,
    ];
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Kind::BadIndex => "bad vertex indices",
            Kind::VertexOutsideGrid => "vertices outside the grid",
            Kind::VertexOnNodata => "vertices on nodata",
            Kind::NonFiniteHeight => "non-finite vertex heights",
            Kind::Unmeasured => "unmeasured triangles",
            Kind::Degenerate => "degenerate triangles",
            Kind::Flipped => "flipped triangles",
            Kind::NodataCovered => "triangles covering nodata",
            Kind::Uncovered => "uncovered domain samples",
            Kind::AreaMismatch => "area mismatches",
            Kind::OpenEdge => "open edges inside the domain",
            Kind::OverlappingEdge => "overlapping edges",
            Kind::ErrorExceeded => "error bound violations",
        })
    }
}

/// Collects problem lines, keeping [`LINES_PER_KIND`] of each kind.
#[derive(Debug, Default)]
pub(crate) struct ProblemLog {
    lines: Vec<String>,
    counts: [u64; Kind::ALL.len()],
}

impl ProblemLog {
    /// Records one finding of `kind`; `line` is only formatted if it will be kept.
    pub(crate) fn push(&mut self, kind: Kind, line: impl FnOnce() -> String) {
        let count = &mut self.counts[kind as usize];
        if *count < LINES_PER_KIND as u64 {
            self.lines.push(line());
        }
        *count += 1;
    }

    /// The kept lines in the order found, then one line per kind that had more.
    pub(crate) fn finish(mut self) -> Vec<String> {
        for kind in Kind::ALL {
            let count = self.counts[kind as usize];
            if count > LINES_PER_KIND as u64 {
                let more = count - LINES_PER_KIND as u64;
                self.lines.push(format!("... and {more} more {kind}"));
            }
        }
        self.lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_first_lines_of_each_kind_and_counts_the_rest() {
        let mut log = ProblemLog::default();
        for i in 0..8 {
            log.push(Kind::Flipped, || format!("flipped {i}"));
        }
        log.push(Kind::Uncovered, || "uncovered".to_string());
        log.push(Kind::Flipped, || {
            unreachable!("not formatted once the kind is full")
        });
        let lines = log.finish();
        assert_eq!(
            lines,
            [
                "flipped 0",
                "flipped 1",
                "flipped 2",
                "flipped 3",
                "flipped 4",
                "uncovered",
                "... and 4 more flipped triangles",
            ]
        );
    }

    #[test]
    fn kinds_index_their_counters() {
        for (i, kind) in Kind::ALL.into_iter().enumerate() {
            assert_eq!(kind as usize, i);
        }
    }
}
