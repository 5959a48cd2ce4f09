//! Edge flips that lower triangle errors, each followed by another sweep (beyond the paper).
//! Vertex removal keeps whatever triangulation its holes left; flipping an edge
//! into the other diagonal of its quadrilateral where both new triangles fit better
//! changes the stars of the four corners, and some of them can then go.

use crate::exact::triangle_error;
use crate::hole::Rules;
use crate::mesh::{Mesh, NONE};
use crate::predicates::{orient, Point};

/// A flip must bring the larger error of the two triangles below this fraction of what it
/// was: small gains are not worth a rasterization and would make passes long.
const FLIP_GAIN: f64 = 0.9;

/// One pass over the interior edges in triangle slot order: flips an edge into the other
/// diagonal of its strictly convex quadrilateral when both new triangles' exact errors are
/// within the limit, within the longest edge allowed, and below [`FLIP_GAIN`] times the
/// larger bound of the two old triangles (never where it is 0 or subnormal). Each triangle flips at most
/// once per pass. The largest bound never grows, and every flip lowers the larger of its
/// two, so rounds come to an end. Returns the number of flips.
pub(crate) fn flip_for_error(mesh: &mut Mesh<'_>, rules: &Rules<'_>) -> usize {
    let mut flips = 0;
    for t in 0..mesh.triangle_slots() as u32 {
        if mesh.corners(t)[0] == NONE {
            continue;
        }
        for j in 0..3 {
            let Some((u, quad)) = mesh.quad(t, j) else {
                continue;
            };
            if u < t {
                continue; // each edge once, from its lower slot
            }
            let points = quad.map(|v| mesh.point(v));
            let old = mesh.bound(t).max().max(mesh.bound(u).max());
            if old < f64::MIN_POSITIVE {
                // Nothing to gain at 0, and below the normal range 0.9 x old can round
                // back to old: flipping would only undo itself next round.
                continue;
            }
            if !flip_within(
                mesh,
                rules,
                t,
                j,
                &points,
                (FLIP_GAIN * old).min(rules.limit),
            ) {
                continue;
            }
            flips += 1;
            break; // t has changed: its other edges wait for the next pass
        }
    }
    flips
}

/// Flips edge `j` of live triangle `t`, whose quadrilateral has the corner `points` of
/// [`Mesh::quad`], into the other diagonal when the quadrilateral is strictly convex, the
/// new edge is within the longest edge allowed and both new triangles' exact errors are
/// within `cap`. Returns whether it flipped.
pub(crate) fn flip_within(
    mesh: &mut Mesh<'_>,
    rules: &Rules<'_>,
    t: u32,
    j: usize,
    points: &[Point; 4],
    cap: f64,
) -> bool {
    let [pa, pb, pc, pd] = points;
    if orient(pc, pa, pd) <= 0
        || orient(pc, pd, pb) <= 0
        || !rules.edge_limit.allows(pc, pd)
        || !rules.edge_limit.faces_out(pc, pa, pd)
        || !rules.edge_limit.faces_out(pc, pd, pb)
    {
        return false;
    }
    let Some(first) = triangle_error(rules.grid, pc, pa, pd, cap) else {
        return false;
    };
    let Some(second) = triangle_error(rules.grid, pc, pd, pb, cap) else {
        return false;
    };
    mesh.flip(t, j, [first, second]);
    true
}
