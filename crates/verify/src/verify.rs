//! The brute-force check itself: vertices, triangles, every covered sample, then coverage.

use crate::coverage::Coverage;
use crate::edges::check_edges;
use crate::predicates::{interpolate, orient};
use crate::problems::{Kind, ProblemLog};
use crate::scan_convert::rasterize;
use crate::{ErrorLocation, GridRef, MeshRef, Report, Result, VerifyError, VerifyOptions};

/// Checks `mesh` against `grid`: structure, coverage of the domain, and the true vertical
/// error at every sample each triangle covers.
///
/// In order:
/// 1. every vertex lies inside the grid on a valid sample and has a finite height, and
///    every triangle index is below `positions.len()`;
/// 2. no triangle is degenerate (`orient == 0`) or wound against `options.orientation`;
/// 3. every grid sample in each closed triangle (exact integer test) is valid, and its
///    error `|value - interpolation|` is measured, the interpolation using the mesh's own
///    heights; the largest is reported with its location;
/// 4. every domain sample (a corner of a cell whose four corners are valid) is covered;
/// 5. the triangles' doubled areas add up to twice the number of valid cells;
/// 6. the mesh conforms: each edge inside the domain is shared by two triangles, one on
///    each side, and every other edge lies on the domain's outline (vertices with the
///    same position and height are welded first).
///
/// Triangles with a bad index or a corner outside the grid are counted as unmeasured and
/// otherwise skipped, as are those past the point where the triangles' summed area exceeds
/// twice the grid's (they overlap; their area still counts); degenerate triangles cover
/// nothing; flipped triangles are still measured. Findings never make this
/// function fail: they go in the [`Report`]. Deterministic: same input, same report.
///
/// # Errors
/// [`VerifyError::GridSize`] if `grid.values.len() != width * height`, and
/// [`VerifyError::MeshSize`] if `mesh.heights.len() != mesh.positions.len()`.
///
/// # Runtime
/// Linear in the number of samples plus the total number of samples inside measured
/// triangles (at most about three times the grid's, see above; plus one step per triangle
/// row), and a counting sort of the triangles' edges by their
/// lower vertex. Memory: one bit per sample plus a few rows, and about 20 bytes per
/// triangle for the edges (4 per side, and bucket offsets and welded ids per vertex).
pub fn verify(grid: GridRef<'_>, mesh: MeshRef<'_>, options: &VerifyOptions) -> Result<Report> {
    let expected = grid.sample_count();
    if u64::try_from(grid.values.len()) != Ok(expected) {
        return Err(VerifyError::GridSize {
            width: grid.width,
            height: grid.height,
            expected,
            actual: grid.values.len(),
        });
    }
    if mesh.heights.len() != mesh.positions.len() {
        return Err(VerifyError::MeshSize {
            positions: mesh.positions.len(),
            heights: mesh.heights.len(),
        });
    }
    let mut report = Report {
        width: grid.width,
        height: grid.height,
        valid_samples: 0,
        domain_samples: 0,
        isolated_samples: 0,
        valid_cells: 0,
        vertices: mesh.positions.len() as u64,
        triangles: mesh.triangles.len() as u64,
        orientation: options.orientation,
        max_error: 0.0,
        max_error_at: None,
        max_error_allowed: options.max_error,
        uncovered_samples: 0,
        first_uncovered: None,
        degenerate_triangles: 0,
        flipped_triangles: 0,
        unmeasured_triangles: 0,
        nodata_covered_samples: 0,
        first_nodata_covered: None,
        bad_vertices: 0,
        bad_indices: 0,
        domain_area_x2: 0,
        mesh_area_x2: 0,
        open_edges: 0,
        overlapping_edges: 0,
        problems: Vec::new(),
    };
    let mut log = ProblemLog::default();
    let inside = check_vertices(grid, mesh, &mut report, &mut log);
    // Fits in usize: `values` has this many elements.
    let mut covered = Coverage::new(expected as usize);
    let measured = check_triangles(
        grid,
        mesh,
        options,
        &inside,
        &mut covered,
        &mut report,
        &mut log,
    );
    check_samples(grid, &covered, &mut report, &mut log);

    report.domain_area_x2 = 2 * u128::from(report.valid_cells);
    if report.mesh_area_x2 != report.domain_area_x2 {
        log.push(Kind::AreaMismatch, || {
            format!(
                "mesh area x2 is {} but domain area x2 is {}",
                report.mesh_area_x2, report.domain_area_x2
            )
        });
    }
    check_edges(grid, mesh, &measured, &mut report, &mut log);
    if !report.within_bound() {
        log.push(Kind::ErrorExceeded, || {
            let at = report.max_error_at.map_or(String::new(), |at| {
                format!(
                    " at ({}, {}) in triangle {} (sample {}, mesh {})",
                    at.x, at.y, at.triangle, at.sample, at.interpolated
                )
            });
            let allowed = report.max_error_allowed.unwrap_or(f64::NAN);
            format!(
                "max error {}{at} exceeds the allowed {allowed}",
                report.max_error
            )
        });
    }
    report.problems = log.finish();
    let measured_count = measured.iter().filter(|&&m| m).count() as u64;
    if report.flipped_triangles > 1 && report.flipped_triangles == measured_count {
        report.problems.insert(
            0,
            "every triangle is wound the other way round (the mesh faces down); reverse \
             each triangle's corners"
                .to_owned(),
        );
    }
    Ok(report)
}

/// Check 1 on vertices; returns which vertices lie inside the grid.
fn check_vertices(
    grid: GridRef<'_>,
    mesh: MeshRef<'_>,
    report: &mut Report,
    log: &mut ProblemLog,
) -> Vec<bool> {
    let mut inside = Vec::with_capacity(mesh.positions.len());
    for (v, (&[x, y], &z)) in mesh.positions.iter().zip(mesh.heights).enumerate() {
        let mut bad = false;
        let in_grid = grid.contains(x, y);
        if !in_grid {
            bad = true;
            log.push(Kind::VertexOutsideGrid, || {
                format!(
                    "vertex {v} at ({x}, {y}) is outside the {}x{} grid",
                    grid.width, grid.height
                )
            });
        } else if !grid.is_valid(x as u32, y as u32) {
            bad = true;
            log.push(Kind::VertexOnNodata, || {
                format!("vertex {v} at ({x}, {y}) is on a nodata sample")
            });
        }
        if !z.is_finite() {
            bad = true;
            log.push(Kind::NonFiniteHeight, || {
                format!("vertex {v} at ({x}, {y}) has non-finite height {z}")
            });
        }
        report.bad_vertices += u64::from(bad);
        inside.push(in_grid);
    }
    inside
}

/// Checks 1 (indices), 2 and 3: orientation, then every sample inside each triangle.
/// Returns which triangles were measured (corners in the grid, not degenerate).
fn check_triangles(
    grid: GridRef<'_>,
    mesh: MeshRef<'_>,
    options: &VerifyOptions,
    inside: &[bool],
    covered: &mut Coverage,
    report: &mut Report,
    log: &mut ProblemLog,
) -> Vec<bool> {
    let vertex_count = mesh.positions.len();
    let mut measured = vec![false; mesh.triangles.len()];
    // Twice the doubled area of the grid's rectangle of sample centres.
    let overlap_cap_x2 =
        4 * u128::from(grid.width.saturating_sub(1)) * u128::from(grid.height.saturating_sub(1));
    for (t, &corners) in mesh.triangles.iter().enumerate() {
        let mut measurable = true;
        for (corner, &v) in corners.iter().enumerate() {
            if v as usize >= vertex_count {
                measurable = false;
                report.bad_indices += 1;
                log.push(Kind::BadIndex, || {
                    format!(
                        "triangle {t} corner {corner} is vertex {v}, but there are {vertex_count} vertices"
                    )
                });
            } else if !inside[v as usize] {
                measurable = false;
                log.push(Kind::Unmeasured, || {
                    format!("triangle {t} not measured: its vertex {v} is outside the grid")
                });
            }
        }
        if !measurable {
            report.unmeasured_triangles += 1;
            continue;
        }
        let [a, b, c] = corners.map(|v| mesh.positions[v as usize]);
        let area_x2 = orient(a, b, c);
        if area_x2 == 0 {
            report.degenerate_triangles += 1;
            log.push(Kind::Degenerate, || {
                format!("triangle {t} is degenerate: {} {} {}", at(a), at(b), at(c))
            });
            continue;
        }
        if area_x2.signum() != options.orientation.sign() {
            report.flipped_triangles += 1;
            log.push(Kind::Flipped, || {
                format!(
                    "triangle {t} is flipped: {} {} {} is not {} (columns, rows)",
                    at(a),
                    at(b),
                    at(c),
                    options.orientation
                )
            });
        }
        report.mesh_area_x2 += area_x2.unsigned_abs();
        if report.mesh_area_x2 > overlap_cap_x2 {
            // No valid mesh gets here (its area is the domain's, at most the grid's), and
            // measuring on would let a small file of stacked copies of one large triangle
            // cost (triangles x grid samples).
            report.unmeasured_triangles += 1;
            log.push(Kind::Unmeasured, || {
                format!(
                    "triangle {t} not measured: with it the triangles cover more than twice \
                     the grid's area, so they overlap"
                )
            });
            continue;
        }
        measured[t] = true;

        let z = corners.map(|v| mesh.heights[v as usize]);
        let mut nodata_logged = false;
        rasterize([a, b, c], grid.width, grid.height, |x, y, weights| {
            let i = grid.index(x, y);
            covered.insert(i);
            let sample = grid.values[i];
            if !sample.is_finite() {
                if !nodata_logged {
                    nodata_logged = true;
                    log.push(Kind::NodataCovered, || {
                        format!("triangle {t} covers nodata sample ({x}, {y})")
                    });
                }
                return;
            }
            let interpolated = interpolate(weights, z);
            let error = (sample - interpolated).abs();
            let error = if error.is_nan() { f64::INFINITY } else { error };
            if report.max_error_at.is_none() || error > report.max_error {
                report.max_error = error;
                report.max_error_at = Some(ErrorLocation {
                    x,
                    y,
                    sample,
                    interpolated,
                    triangle: t,
                });
            }
        });
    }
    measured
}

/// Counts samples and cells, and checks 4 (coverage) and nodata coverage per sample.
fn check_samples(grid: GridRef<'_>, covered: &Coverage, report: &mut Report, log: &mut ProblemLog) {
    if grid.sample_count() == 0 {
        return;
    }
    let width = grid.width as usize;
    // Valid samples of row y; rows outside the grid have none.
    let sample_row = |y: u32| -> Vec<bool> {
        if y < grid.height {
            (0..grid.width).map(|x| grid.is_valid(x, y)).collect()
        } else {
            vec![false; width]
        }
    };
    // Valid cells between two rows of samples: width - 1 of them.
    let cells = |top: &[bool], bottom: &[bool]| -> Vec<bool> {
        (1..width)
            .map(|x| top[x - 1] && top[x] && bottom[x - 1] && bottom[x])
            .collect()
    };
    let touches = |row: &[bool], x: usize| (x > 0 && row[x - 1]) || row.get(x) == Some(&true);
    let mut valid = sample_row(0);
    let mut above = vec![false; width.saturating_sub(1)];
    for y in 0..grid.height {
        let next = sample_row(y + 1);
        let below = cells(&valid, &next);
        report.valid_cells += below.iter().filter(|&&c| c).count() as u64;
        for x in 0..grid.width {
            let i = grid.index(x, y);
            let is_covered = covered.contains(i);
            if !grid.values[i].is_finite() {
                if is_covered {
                    report.nodata_covered_samples += 1;
                    report.first_nodata_covered.get_or_insert([x, y]);
                }
                continue;
            }
            report.valid_samples += 1;
            if !(touches(&above, x as usize) || touches(&below, x as usize)) {
                report.isolated_samples += 1;
                continue;
            }
            report.domain_samples += 1;
            if !is_covered {
                report.uncovered_samples += 1;
                report.first_uncovered.get_or_insert([x, y]);
                log.push(Kind::Uncovered, || {
                    format!("domain sample ({x}, {y}) is covered by no triangle")
                });
            }
        }
        above = below;
        valid = next;
    }
}

/// A position as `(x, y)` for messages.
fn at([x, y]: [i64; 2]) -> String {
    format!("({x}, {y})")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Orientation;

    /// The 8 counter-clockwise triangles of a 3x3 grid, vertex `i` at `(i % 3, i / 3)`:
    /// each cell split along its main diagonal.
    fn grid_positions_3x3() -> Vec<[i64; 2]> {
        (0..9).map(|i| [i % 3, i / 3]).collect()
    }

    fn eight_triangles() -> Vec<[u32; 3]> {
        let mut triangles = Vec::new();
        for y in 0..2u32 {
            for x in 0..2u32 {
                let v = y * 3 + x;
                // (x,y) (x+1,y+1) (x+1,y) and (x,y) (x,y+1) (x+1,y+1): orient > 0.
                triangles.push([v, v + 1, v + 4]);
                triangles.push([v, v + 4, v + 3]);
            }
        }
        triangles
    }

    fn heights_of(values: &[f64], positions: &[[i64; 2]], width: i64) -> Vec<f64> {
        positions
            .iter()
            .map(|&[x, y]| values[(y * width + x) as usize])
            .collect()
    }

    fn run(
        width: u32,
        height: u32,
        values: &[f64],
        positions: &[[i64; 2]],
        heights: &[f64],
        triangles: &[[u32; 3]],
        options: VerifyOptions,
    ) -> Report {
        let grid = GridRef::new(width, height, values);
        let mesh = MeshRef::new(positions, heights, triangles);
        verify(grid, mesh, &options).expect("consistent lengths")
    }

    /// [`run`] on the flat 3x3 grid with its nine vertices (all heights 0) and
    /// `triangles`.
    fn flat_3x3(triangles: &[[u32; 3]]) -> Report {
        let positions = grid_positions_3x3();
        run(
            3,
            3,
            &[0.0; 9],
            &positions,
            &[0.0; 9],
            triangles,
            VerifyOptions::new(),
        )
    }

    #[test]
    fn eight_triangles_on_a_plane_are_exact() {
        let values: Vec<f64> = (0..9)
            .map(|i| 1.0 + 2.0 * (i % 3) as f64 - 0.5 * (i / 3) as f64)
            .collect();
        let positions = grid_positions_3x3();
        let heights = heights_of(&values, &positions, 3);
        let triangles = eight_triangles();
        for t in &triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            assert!(orient(a, b, c) > 0, "fixture must be counter-clockwise");
        }
        let options = VerifyOptions::new().with_max_error(0.0);
        let report = run(3, 3, &values, &positions, &heights, &triangles, options);
        assert_eq!(report.max_error, 0.0);
        assert_eq!(report.valid_samples, 9);
        assert_eq!(report.domain_samples, 9);
        assert_eq!(report.isolated_samples, 0);
        assert_eq!(report.valid_cells, 4);
        assert_eq!(report.domain_area_x2, 8);
        assert_eq!(report.mesh_area_x2, 8);
        assert_eq!(report.uncovered_samples, 0);
        assert!(report.max_error_at.is_some());
        assert!(report.problems.is_empty(), "{:?}", report.problems);
        assert!(report.mesh_is_valid());
        assert!(report.within_bound());
        assert!(report.passed());
    }

    #[test]
    fn two_triangles_over_a_bump_find_the_centre() {
        // Flat at 0 except the centre, 4.0; only the four corners are vertices.
        let mut values = vec![0.0; 9];
        values[4] = 4.0;
        let positions = [[0, 0], [2, 0], [2, 2], [0, 2]];
        let heights = [0.0; 4];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let options = VerifyOptions::new().with_max_error(3.5);
        let report = run(3, 3, &values, &positions, &heights, &triangles, options);
        assert_eq!(report.max_error, 4.0);
        assert_eq!(
            report.max_error_at,
            Some(ErrorLocation {
                x: 1,
                y: 1,
                sample: 4.0,
                interpolated: 0.0,
                triangle: 0,
            })
        );
        assert!(report.mesh_is_valid(), "{:?}", report.problems);
        assert!(!report.within_bound());
        assert!(!report.passed());
        assert_eq!(report.problems.len(), 1);
        assert!(
            report.problems[0].contains("max error 4"),
            "{:?}",
            report.problems
        );
        assert!(
            report.problems[0].contains("(1, 1)"),
            "{:?}",
            report.problems
        );
    }

    #[test]
    fn non_planar_interpolation_is_measured_exactly() {
        // z = x * y on a 3x3 grid, two triangles over the corners 0, 2, 8, 6 with heights
        // 0, 0, 4, 0. Sample (1, 1) lies on the diagonal: interpolation 2, value 1.
        // Sample (2, 1) on triangle 0: interpolation 2, value 2. (1, 2): 2 vs 2.
        let values: Vec<f64> = (0..9).map(|i| ((i % 3) * (i / 3)) as f64).collect();
        let positions = [[0, 0], [2, 0], [2, 2], [0, 2]];
        let heights = [0.0, 0.0, 4.0, 0.0];
        let report = run(
            3,
            3,
            &values,
            &positions,
            &heights,
            &[[0, 1, 2], [0, 2, 3]],
            VerifyOptions::new(),
        );
        assert_eq!(report.max_error, 1.0);
        let at = report.max_error_at.expect("samples were measured");
        assert_eq!((at.x, at.y, at.sample, at.interpolated), (1, 1, 1.0, 2.0));
        assert!(report.passed(), "no bound given, valid mesh");
    }

    #[test]
    fn missing_triangle_leaves_a_hole() {
        let values = vec![0.0; 9];
        let positions = grid_positions_3x3();
        let heights = vec![0.0; 9];
        let mut triangles = eight_triangles();
        // Drop both triangles of the bottom-right cell: its corner (2, 2) is in no other.
        triangles.retain(|t| !t.contains(&8));
        let report = run(
            3,
            3,
            &values,
            &positions,
            &heights,
            &triangles,
            VerifyOptions::new(),
        );
        assert_eq!(report.uncovered_samples, 1);
        assert_eq!(report.first_uncovered, Some([2, 2]));
        assert_eq!(report.domain_area_x2, 8);
        assert_eq!(report.mesh_area_x2, 6);
        assert!(!report.mesh_is_valid());
        assert!(report.within_bound());
        assert!(!report.passed());
        assert!(report.problems.iter().any(|p| p.contains("(2, 2)")));
        assert!(report
            .problems
            .iter()
            .any(|p| p.contains("mesh area x2 is 6")));
    }

    #[test]
    fn half_cell_missing_is_an_area_mismatch_without_uncovered_samples() {
        let mut triangles = eight_triangles();
        triangles.remove(7); // (1,1) (2,2) (1,2): its corners stay covered.
        let report = flat_3x3(&triangles);
        assert_eq!(report.uncovered_samples, 0);
        assert_eq!(report.mesh_area_x2, 7);
        assert!(!report.mesh_is_valid());
    }

    #[test]
    fn a_hole_balanced_by_an_overlap_is_caught_by_the_edges() {
        // Area and coverage agree (a half cell gone, another covered twice); only the
        // edges tell: the hole's two inner sides border one triangle inside the domain
        // (its third is on the outline), and the repeated triangle's three sides are
        // each shared on the same side.
        let mut triangles = eight_triangles();
        triangles.remove(7); // (1,1) (2,2) (1,2)
        triangles.push([0, 1, 4]); // a second (0,0) (1,0) (1,1)
        let report = flat_3x3(&triangles);
        assert_eq!(report.uncovered_samples, 0);
        assert_eq!(report.mesh_area_x2, report.domain_area_x2);
        assert_eq!(report.open_edges, 2);
        assert_eq!(report.overlapping_edges, 3);
        assert!(!report.mesh_is_valid());
        assert!(report.problems.iter().any(|p| p.contains("overlap")));
    }

    #[test]
    fn a_t_junction_and_a_repeated_vertex_are_open_edges() {
        // 3x3 grid: the left cells split at (1,1), the right half as two triangles whose
        // long edge (1,0)-(1,2) passes through (1,1): a T-junction.
        let values = vec![0.0; 9];
        let triangles = vec![
            [0, 1, 4],
            [0, 4, 3],
            [3, 4, 7],
            [3, 7, 6],
            [1, 2, 8],
            [1, 8, 7],
        ];
        let report = flat_3x3(&triangles);
        assert_eq!(report.mesh_area_x2, report.domain_area_x2);
        assert_eq!(report.open_edges, 3, "{:?}", report.problems);
        assert!(!report.mesh_is_valid());

        // The same grid with the centre vertex repeated at another height in the right
        // cells: a step in the surface.
        let mut positions = grid_positions_3x3();
        positions.push([1, 1]);
        let mut heights = vec![0.0; 9];
        heights.push(0.25);
        let mut triangles = eight_triangles();
        for t in [3, 6, 7] {
            for v in triangles[t].iter_mut().filter(|v| **v == 4) {
                *v = 9;
            }
        }
        let report = run(
            3,
            3,
            &values,
            &positions,
            &heights,
            &triangles,
            VerifyOptions::new(),
        );
        assert!(report.open_edges > 0);
        assert!(!report.mesh_is_valid());
    }

    #[test]
    fn long_outline_edges_and_nodata_holes_conform() {
        // A 5x4 grid with a nodata sample inside: the mesh is the ring of cells around the
        // hole's four cells, its border edges long (several cells) on the raster's edge.
        let (w, h) = (5u32, 4u32);
        let mut values = vec![1.0; (w * h) as usize];
        values[(w + 2) as usize] = f64::NAN; // (2, 1)
        let p = |x: i64, y: i64| [x, y];
        // Without the hole: two triangles over the whole rectangle.
        let positions = vec![p(0, 0), p(4, 0), p(4, 3), p(0, 3)];
        let all_valid = vec![1.0; (w * h) as usize];
        let report = run(
            w,
            h,
            &all_valid,
            &positions,
            &[1.0; 4],
            &[[0, 1, 2], [0, 2, 3]],
            VerifyOptions::new(),
        );
        assert!(report.passed(), "{:?}", report.problems);
        // The hole: cells (1..3, 0..2) are invalid. Triangles around it, with the hole's
        // outline edges used once and the domain on their side.
        let positions = vec![
            p(0, 0),
            p(1, 0),
            p(3, 0),
            p(4, 0),
            p(1, 2),
            p(3, 2),
            p(0, 3),
            p(4, 3),
        ];
        let triangles = vec![
            [0, 1, 4], // left strip, top
            [0, 4, 6], // left strip
            [4, 5, 7], // below the hole
            [4, 7, 6],
            [2, 3, 7], // right strip
            [2, 7, 5],
        ];
        let report = run(
            w,
            h,
            &values,
            &positions,
            &[1.0; 8],
            &triangles,
            VerifyOptions::new(),
        );
        assert_eq!(report.open_edges, 0, "{:?}", report.problems);
        assert_eq!(report.overlapping_edges, 0);
        assert!(report.passed(), "{:?}", report.problems);
    }

    #[test]
    fn flipped_triangle_is_flagged() {
        let mut triangles = eight_triangles();
        triangles[3].swap(1, 2);
        let report = flat_3x3(&triangles);
        assert_eq!(report.flipped_triangles, 1);
        assert_eq!(report.degenerate_triangles, 0);
        // Still measured: coverage and area are intact.
        assert_eq!(report.uncovered_samples, 0);
        assert_eq!(report.mesh_area_x2, 8);
        assert!(!report.mesh_is_valid());
        assert_eq!(report.problems.len(), 1);
        assert!(
            report.problems[0].starts_with("triangle 3 is flipped"),
            "{:?}",
            report.problems
        );
    }

    #[test]
    fn a_mesh_wound_the_other_way_round_is_named_as_such() {
        let triangles: Vec<[u32; 3]> = eight_triangles()
            .into_iter()
            .map(|[a, b, c]| [a, c, b])
            .collect();
        let report = flat_3x3(&triangles);
        assert_eq!(report.flipped_triangles, 8);
        assert!(
            report.problems[0].starts_with("every triangle is wound the other way round"),
            "{:?}",
            report.problems
        );
    }

    #[test]
    fn heights_of_zero_and_minus_zero_are_one_vertex() {
        // Two copies of the centre vertex, one at -0.0: welded, no crack between them.
        let (w, h) = (3, 3);
        let values = vec![0.0; 9];
        let mut positions: Vec<[i64; 2]> = (0..9).map(|i| [i % 3, i / 3]).collect();
        positions.push([1, 1]);
        let mut heights = vec![0.0; 9];
        heights.push(-0.0);
        let mut triangles = eight_triangles();
        for t in triangles.iter_mut().step_by(2) {
            for v in t.iter_mut().filter(|v| **v == 4) {
                *v = 9;
            }
        }
        let report = run(
            w,
            h,
            &values,
            &positions,
            &heights,
            &triangles,
            VerifyOptions::new(),
        );
        assert!(report.passed(), "{:?}", report.problems);
    }

    #[test]
    fn degenerate_triangle_is_flagged() {
        let mut triangles = eight_triangles();
        triangles.push([0, 4, 8]); // the main diagonal
        triangles.push([1, 1, 2]); // a repeated corner
        let report = flat_3x3(&triangles);
        assert_eq!(report.degenerate_triangles, 2);
        assert_eq!(report.flipped_triangles, 0);
        assert_eq!(report.mesh_area_x2, 8);
        assert!(!report.mesh_is_valid());
        assert!(report.problems[0].starts_with("triangle 8 is degenerate"));
    }

    #[test]
    fn triangle_over_nodata_is_flagged() {
        // Sample (1, 1) is nodata: the domain is empty (every cell touches it), so the
        // corners are isolated, and the two big triangles cover the hole.
        let mut values = vec![1.0; 9];
        values[4] = f64::NAN;
        let positions = [[0, 0], [2, 0], [2, 2], [0, 2]];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let report = run(
            3,
            3,
            &values,
            &positions,
            &[1.0; 4],
            &triangles,
            VerifyOptions::new(),
        );
        assert_eq!(report.nodata_covered_samples, 1);
        assert_eq!(report.first_nodata_covered, Some([1, 1]));
        assert_eq!(report.valid_cells, 0);
        assert_eq!(report.domain_samples, 0);
        assert_eq!(report.isolated_samples, 8);
        assert_eq!(report.max_error, 0.0, "valid samples are still measured");
        assert!(!report.mesh_is_valid());
        assert!(report
            .problems
            .contains(&"triangle 0 covers nodata sample (1, 1)".to_string()));
        assert!(report
            .problems
            .contains(&"triangle 1 covers nodata sample (1, 1)".to_string()));
    }

    #[test]
    fn wrong_vertex_height_is_an_error() {
        let values: Vec<f64> = (0..9).map(|i| i as f64).collect();
        let positions = grid_positions_3x3();
        let mut heights = heights_of(&values, &positions, 3);
        heights[5] += 0.75; // vertex at (2, 1)
        let options = VerifyOptions::new().with_max_error(0.5);
        let report = run(
            3,
            3,
            &values,
            &positions,
            &heights,
            &eight_triangles(),
            options,
        );
        assert_eq!(report.max_error, 0.75);
        let at = report.max_error_at.expect("measured");
        assert_eq!((at.x, at.y, at.sample, at.interpolated), (2, 1, 5.0, 5.75));
        assert!(report.mesh_is_valid());
        assert!(!report.passed());
    }

    #[test]
    fn clockwise_mesh_accepted_when_asked_for() {
        let values = vec![2.0; 9];
        let positions = grid_positions_3x3();
        let clockwise: Vec<[u32; 3]> = eight_triangles()
            .iter()
            .map(|&[a, b, c]| [a, c, b])
            .collect();
        let cw = VerifyOptions::new().with_orientation(Orientation::Clockwise);
        let report = run(3, 3, &values, &positions, &[2.0; 9], &clockwise, cw);
        assert_eq!(report.flipped_triangles, 0);
        assert!(report.passed(), "{:?}", report.problems);
        // The same mesh against the default: all eight flipped.
        let report = run(
            3,
            3,
            &values,
            &positions,
            &[2.0; 9],
            &clockwise,
            VerifyOptions::new(),
        );
        assert_eq!(report.flipped_triangles, 8);
        assert!(!report.passed());
        assert!(report
            .problems
            .contains(&"... and 3 more flipped triangles".to_string()));
    }

    #[test]
    fn isolated_samples_are_counted_but_need_no_cover() {
        // 4x3 grid: one valid cell at the top left; (3, 0) and (3, 2) are valid but in no
        // valid cell; (2, 0) is valid but its cells have a nodata corner.
        let n = f64::NAN;
        #[rustfmt::skip]
        let values = [
            1.0, 1.0, 1.0, 1.0,
            1.0, 1.0, n,   n,
            n,   n,   n,   1.0,
        ];
        let positions = [[0, 0], [1, 0], [1, 1], [0, 1]];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let report = run(
            4,
            3,
            &values,
            &positions,
            &[1.0; 4],
            &triangles,
            VerifyOptions::new(),
        );
        assert_eq!(report.valid_samples, 7);
        assert_eq!(report.valid_cells, 1);
        assert_eq!(report.domain_samples, 4);
        assert_eq!(report.isolated_samples, 3);
        assert_eq!(report.uncovered_samples, 0);
        assert!(report.passed(), "{:?}", report.problems);
    }

    #[test]
    fn domain_samples_of_diagonal_cells() {
        // Two valid cells touching only at (1, 1); every valid sample is a domain sample.
        let mut values = [0.0; 9];
        values[2] = f64::NAN; // (2, 0): cell (1, 0) is invalid
        values[6] = f64::NAN; // (0, 2): cell (0, 1) is invalid
        let report = run(3, 3, &values, &[], &[], &[], VerifyOptions::new());
        assert_eq!(report.valid_cells, 2);
        assert_eq!(report.domain_samples, 7);
        assert_eq!(report.isolated_samples, 0);
        assert_eq!(report.uncovered_samples, 7);
        assert_eq!(report.first_uncovered, Some([0, 0]));
        assert_eq!(report.max_error_at, None);
    }

    #[test]
    fn empty_mesh_on_empty_domain_is_valid() {
        let values = [f64::NAN, 1.0, f64::NAN, f64::NAN];
        let report = run(
            2,
            2,
            &values,
            &[],
            &[],
            &[],
            VerifyOptions::new().with_max_error(0.0),
        );
        assert_eq!(report.valid_samples, 1);
        assert_eq!(report.isolated_samples, 1);
        assert_eq!(report.domain_area_x2, 0);
        assert_eq!(report.mesh_area_x2, 0);
        assert!(report.passed());
        let report = run(0, 0, &[], &[], &[], &[], VerifyOptions::new());
        assert!(report.passed());
    }

    #[test]
    fn bad_vertices_and_indices_are_reported() {
        let mut values = vec![0.0; 9];
        values[4] = f64::NAN;
        let positions = [[0, 0], [2, 0], [1, 1], [0, 3], [-1, 0], [2, 2]];
        let heights = [0.0, 0.0, 0.0, 0.0, 0.0, f64::INFINITY];
        let triangles = [[0, 1, 3], [0, 1, 9], [0, 1, 5]];
        let report = run(
            3,
            3,
            &values,
            &positions,
            &heights,
            &triangles,
            VerifyOptions::new(),
        );
        // (1,1) on nodata, (0,3) and (-1,0) outside, (2,2) has an infinite height.
        assert_eq!(report.bad_vertices, 4);
        assert_eq!(report.bad_indices, 1);
        assert_eq!(report.unmeasured_triangles, 2);
        // The third triangle is measured; its infinite height yields an infinite error.
        assert_eq!(report.max_error, f64::INFINITY);
        assert!(!report.mesh_is_valid());
        let expected = [
            "vertex 2 at (1, 1) is on a nodata sample",
            "vertex 3 at (0, 3) is outside the 3x3 grid",
            "vertex 4 at (-1, 0) is outside the 3x3 grid",
            "vertex 5 at (2, 2) has non-finite height inf",
            "triangle 0 not measured: its vertex 3 is outside the grid",
            "triangle 1 corner 2 is vertex 9, but there are 6 vertices",
        ];
        for line in expected {
            assert!(
                report.problems.iter().any(|p| p == line),
                "missing {line:?} in {:?}",
                report.problems
            );
        }
    }

    #[test]
    fn extreme_vertex_coordinates_do_not_overflow() {
        let values = vec![0.0; 4];
        let positions = [[i64::MIN, i64::MIN], [i64::MAX, 0], [0, i64::MAX], [1, 1]];
        let triangles = [[0, 1, 2], [3, 1, 2]];
        let report = run(
            2,
            2,
            &values,
            &positions,
            &[0.0; 4],
            &triangles,
            VerifyOptions::new(),
        );
        assert_eq!(report.bad_vertices, 3);
        assert_eq!(report.unmeasured_triangles, 2);
        assert_eq!(report.uncovered_samples, 4);
        assert!(!report.mesh_is_valid());
    }

    #[test]
    fn long_strip_with_large_coordinates() {
        // A 1_000_001 x 2 strip on the plane z = 1e-3 x + y, with one bump of +5 at
        // (500_000, 1), covered by two sliver triangles spanning the whole strip.
        let width: u32 = 1_000_001;
        let last = i64::from(width) - 1;
        let plane = |x: i64, y: i64| 1e-3 * x as f64 + y as f64;
        let mut values: Vec<f64> = (0..2)
            .flat_map(|y| (0..=last).map(move |x| plane(x, y)))
            .collect();
        values[width as usize + 500_000] += 5.0;
        let positions = [[0, 0], [last, 0], [last, 1], [0, 1]];
        let heights = positions.map(|[x, y]| plane(x, y));
        let triangles = [[0, 2, 1], [0, 3, 2]];
        let options = VerifyOptions::new()
            .with_orientation(Orientation::Clockwise)
            .with_max_error(5.0 + 1e-6);
        let report = run(width, 2, &values, &positions, &heights, &triangles, options);
        assert_eq!(report.valid_cells, u64::from(width) - 1);
        assert_eq!(report.domain_area_x2, 2 * u128::from(width - 1));
        assert_eq!(report.mesh_area_x2, report.domain_area_x2);
        assert_eq!(report.uncovered_samples, 0);
        let at = report.max_error_at.expect("measured");
        assert_eq!((at.x, at.y, at.triangle), (500_000, 1, 1));
        assert!(
            (report.max_error - 5.0).abs() < 1e-6,
            "{}",
            report.max_error
        );
        assert!(report.passed(), "{:?}", report.problems);
        // Without the bump the plane is reproduced to rounding.
        values[width as usize + 500_000] -= 5.0;
        let report = run(
            width,
            2,
            &values,
            &positions,
            &heights,
            &triangles,
            options.with_max_error(1e-9),
        );
        assert!(report.passed(), "max error {}", report.max_error);
    }

    #[test]
    fn inconsistent_lengths_are_errors() {
        let grid = GridRef::new(2, 2, &[0.0; 3]);
        let mesh = MeshRef::new(&[], &[], &[]);
        assert_eq!(
            verify(grid, mesh, &VerifyOptions::new()).unwrap_err(),
            VerifyError::GridSize {
                width: 2,
                height: 2,
                expected: 4,
                actual: 3
            }
        );
        let grid = GridRef::new(2, 2, &[0.0; 4]);
        let mesh = MeshRef::new(&[[0, 0]], &[], &[]);
        assert_eq!(
            verify(grid, mesh, &VerifyOptions::new()).unwrap_err(),
            VerifyError::MeshSize {
                positions: 1,
                heights: 0
            }
        );
    }

    #[test]
    fn overlapping_triangles_show_as_excess_area() {
        let mut triangles = eight_triangles();
        triangles.push(triangles[0]);
        let report = flat_3x3(&triangles);
        assert_eq!(report.mesh_area_x2, 9);
        assert!(!report.mesh_is_valid());
        assert_eq!(
            report.unmeasured_triangles, 0,
            "still measured within twice the area"
        );
    }

    #[test]
    fn stacked_copies_stop_being_measured_past_twice_the_grid_area() {
        // Each copy of the eight triangles covers the whole 3x3 grid (area x2 = 8): the
        // first two copies are measured, the rest are counted as unmeasured overlaps.
        let triangles: Vec<[u32; 3]> = eight_triangles().repeat(5);
        let report = flat_3x3(&triangles);
        assert_eq!(report.mesh_area_x2, 40);
        assert_eq!(report.unmeasured_triangles, 24);
        assert!(!report.passed());
        assert!(report
            .problems
            .iter()
            .any(|p| p.contains("triangle 16 not measured")));
    }
}
