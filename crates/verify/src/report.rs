//! What the verifier found: counts, the maximum error and where it is, and the problems.

use serde::Serialize;

use crate::Orientation;

/// Where the maximum error was found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorLocation {
    /// Column of the sample.
    pub x: u32,
    /// Row of the sample.
    pub y: u32,
    /// The grid's value at the sample.
    pub sample: f64,
    /// The mesh's linear interpolation at the sample.
    pub interpolated: f64,
    /// Index of the triangle that interpolated it.
    pub triangle: usize,
}

/// The findings of [`verify`](crate::verify).
///
/// Counts are exact. The *domain* is the union of valid cells (unit squares whose four
/// corners are finite); a *domain sample* is a corner of a valid cell. [`Report::passed`]
/// is the single yes/no answer; [`Report::problems`] says why not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// Grid columns.
    pub width: u32,
    /// Grid rows.
    pub height: u32,
    /// Samples with a finite value.
    pub valid_samples: u64,
    /// Valid samples that are a corner of at least one valid cell.
    pub domain_samples: u64,
    /// Valid samples in no valid cell: they cannot be triangulated, so need no cover.
    pub isolated_samples: u64,
    /// Cells whose four corners are valid.
    pub valid_cells: u64,
    /// Mesh vertices.
    pub vertices: u64,
    /// Mesh triangles.
    pub triangles: u64,
    /// Orientation the triangles were required to have.
    pub orientation: Orientation,
    /// Largest `|sample - interpolation|` over every valid sample in a measured triangle;
    /// `0.0` when none was measured, `+inf` if an interpolation was NaN.
    pub max_error: f64,
    /// Where [`Report::max_error`] was first reached; `None` when no sample was measured.
    pub max_error_at: Option<ErrorLocation>,
    /// The bound the error was checked against, if any.
    pub max_error_allowed: Option<f64>,
    /// Domain samples covered by no measured triangle.
    pub uncovered_samples: u64,
    /// The first uncovered domain sample `[x, y]` in row-major order.
    pub first_uncovered: Option<[u32; 2]>,
    /// Triangles with zero area (collinear or repeated corners).
    pub degenerate_triangles: u64,
    /// Triangles with the orientation opposite to [`Report::orientation`].
    pub flipped_triangles: u64,
    /// Triangles not measured because a corner index is out of range or a corner lies
    /// outside the grid (their samples count as uncovered and their area as zero), or
    /// because the triangles before them already cover twice the grid's area (their area
    /// counts).
    pub unmeasured_triangles: u64,
    /// Distinct nodata samples inside at least one triangle.
    pub nodata_covered_samples: u64,
    /// The first covered nodata sample `[x, y]` in row-major order.
    pub first_nodata_covered: Option<[u32; 2]>,
    /// Vertices outside the grid, on a nodata sample, or with a non-finite height.
    pub bad_vertices: u64,
    /// Triangle corners whose vertex index is not below [`Report::vertices`].
    pub bad_indices: u64,
    /// Twice the domain area: `2 * valid_cells`.
    pub domain_area_x2: u128,
    /// Sum over measured, non-degenerate triangles of twice their area, `|orient|`.
    pub mesh_area_x2: u128,
    /// Edges used by one (measured, non-degenerate) triangle that do not lie on the
    /// domain's outline with the domain on that triangle's side: holes, cracks,
    /// T-junctions, a vertex repeated with another height.
    pub open_edges: u64,
    /// Edges shared by two triangles on the same side of them, or by more than two.
    pub overlapping_edges: u64,
    /// One line per problem found, the first few of each kind, with positions.
    pub problems: Vec<String>,
}

impl Report {
    /// Whether the mesh is a valid triangulation of the domain: every vertex and index is
    /// good, no triangle is degenerate or flipped, no nodata sample is covered, every domain
    /// sample is covered, the mesh area equals the domain area, and the mesh conforms:
    /// every edge inside the domain is shared by two triangles, one on each side, and
    /// every other edge lies on the domain's outline. Consistently oriented triangles whose
    /// only free edges are the outline, with the domain's area, cover it exactly once.
    pub fn mesh_is_valid(&self) -> bool {
        self.bad_vertices == 0
            && self.bad_indices == 0
            && self.unmeasured_triangles == 0
            && self.degenerate_triangles == 0
            && self.flipped_triangles == 0
            && self.nodata_covered_samples == 0
            && self.uncovered_samples == 0
            && self.mesh_area_x2 == self.domain_area_x2
            && self.open_edges == 0
            && self.overlapping_edges == 0
    }

    /// Whether the measured error respects [`Report::max_error_allowed`]; always true when
    /// no bound was given. Says nothing about the mesh's validity: see [`Report::passed`].
    pub fn within_bound(&self) -> bool {
        self.max_error_allowed
            .is_none_or(|allowed| self.max_error <= allowed)
    }

    /// [`Report::mesh_is_valid`] and [`Report::within_bound`]: the mesh tiles the domain and
    /// every domain sample is within the bound of the mesh's interpolation.
    pub fn passed(&self) -> bool {
        self.mesh_is_valid() && self.within_bound()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clean() -> Report {
        Report {
            width: 2,
            height: 2,
            valid_samples: 4,
            domain_samples: 4,
            isolated_samples: 0,
            valid_cells: 1,
            vertices: 4,
            triangles: 2,
            orientation: Orientation::CounterClockwise,
            max_error: 0.25,
            max_error_at: None,
            max_error_allowed: Some(0.5),
            uncovered_samples: 0,
            first_uncovered: None,
            degenerate_triangles: 0,
            flipped_triangles: 0,
            unmeasured_triangles: 0,
            nodata_covered_samples: 0,
            first_nodata_covered: None,
            bad_vertices: 0,
            bad_indices: 0,
            domain_area_x2: 2,
            mesh_area_x2: 2,
            open_edges: 0,
            overlapping_edges: 0,
            problems: Vec::new(),
        }
    }

    #[test]
    fn report_is_serializable() {
        fn serializable<T: Serialize>(_: &T) {}
        serializable(&clean());
        serializable(&ErrorLocation {
            x: 0,
            y: 0,
            sample: 0.0,
            interpolated: 0.0,
            triangle: 0,
        });
    }

    #[test]
    fn clean_report_passes() {
        let report = clean();
        assert!(report.mesh_is_valid());
        assert!(report.within_bound());
        assert!(report.passed());
    }

    #[test]
    fn each_structural_problem_invalidates() {
        let breakers: [fn(&mut Report); 8] = [
            |r| r.bad_vertices = 1,
            |r| r.bad_indices = 1,
            |r| r.unmeasured_triangles = 1,
            |r| r.degenerate_triangles = 1,
            |r| r.flipped_triangles = 1,
            |r| r.nodata_covered_samples = 1,
            |r| r.uncovered_samples = 1,
            |r| r.mesh_area_x2 = 3,
        ];
        for (i, breaker) in breakers.iter().enumerate() {
            let mut report = clean();
            breaker(&mut report);
            assert!(!report.mesh_is_valid(), "breaker {i}");
            assert!(report.within_bound(), "breaker {i}");
            assert!(!report.passed(), "breaker {i}");
        }
    }

    #[test]
    fn bound_is_inclusive_and_optional() {
        let mut report = clean();
        report.max_error = 0.5;
        assert!(report.within_bound());
        report.max_error = 0.5000001;
        assert!(!report.within_bound());
        assert!(report.mesh_is_valid());
        assert!(!report.passed());
        report.max_error_allowed = None;
        assert!(report.passed());
        report.max_error = f64::INFINITY;
        report.max_error_allowed = Some(f64::MAX);
        assert!(!report.within_bound());
    }
}
