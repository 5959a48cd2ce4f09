//! Shaping the TIN for contour lines (beyond the paper): a contour line gets one
//! segment in every triangle its level passes through, so among TINs within the bound,
//! those whose triangles span fewer levels give lines with fewer segments.
//!
//! Three places use the levels: the hole's dynamic program minimizes the levels its
//! triangles span (see `hole.rs`); a removal to a bound is refused when its new triangles
//! span more levels in all than the star's did (`decimate.rs`: it would add segments,
//! and measured, refusing it gives 8–11 % fewer segments for 2–7 % more triangles); and
//! [`flip_for_levels`] runs once no vertex can go. None changes the guarantee: every new
//! triangle's exact error is measured against the same limit.

use crate::flips::flip_within;
use crate::hole::Rules;
use crate::mesh::{Mesh, NONE};
use crate::predicates::{orient, plane_gradient, Point};

/// Number of `levels` (sorted) in `(lo, hi]`: the levels a triangle or edge whose values
/// run from `lo` to `hi` gives a contour segment (up to the degenerate cases at a vertex).
pub(crate) fn levels_spanned(levels: &[f64], lo: f64, hi: f64) -> usize {
    levels.partition_point(|&l| l <= hi) - levels.partition_point(|&l| l <= lo)
}

/// Levels spanned by triangle `abc`.
pub(crate) fn triangle_levels(levels: &[f64], a: &Point, b: &Point, c: &Point) -> usize {
    let lo = a.z.min(b.z).min(c.z);
    let hi = a.z.max(b.z).max(c.z);
    levels_spanned(levels, lo, hi)
}

/// The Dirichlet energy of the plane over counter-clockwise triangle `abc` (twice its
/// area times its squared gradient), the tie-break between triangulations spanning the
/// same levels: summed over a triangulation it is least for the Delaunay one, which
/// avoids slivers.
pub(crate) fn dirichlet_energy(a: &Point, b: &Point, c: &Point) -> f64 {
    let g = plane_gradient(a, b, c);
    (g[0] * g[0] + g[1] * g[1]) * orient(a, b, c) as f64
}

/// Flips interior edges into the other diagonal of their quadrilateral wherever that
/// diagonal spans fewer levels, the quadrilateral is strictly convex, the new edge is
/// within the longest edge allowed, and both new triangles' exact errors are within the
/// limit and no larger than the mesh's largest bound before the pass (so a count-driven
/// run keeps the error it reached). Each flip lowers the total of levels spanned by
/// interior edges, so the pass ends. Boundary edges (the domain's outline, and a tile's
/// shared borders) are never flipped. Returns the number of flips.
pub(crate) fn flip_for_levels(mesh: &mut Mesh<'_>, rules: &Rules<'_>, levels: &[f64]) -> usize {
    let largest = mesh
        .live_triangles()
        .fold(0.0f64, |m, (t, _)| m.max(mesh.bound(t).max()));
    let limit = rules.limit.min(largest);
    let spanned = |p: &Point, q: &Point| levels_spanned(levels, p.z.min(q.z), p.z.max(q.z));
    let slots = mesh.triangle_slots();
    // Triangles to look at, lowest slot first; a flip queues the two changed triangles
    // and their neighbours again.
    let mut queue: Vec<u32> = (0..slots as u32).rev().collect();
    let mut queued = vec![true; slots];
    let mut flips = 0;
    while let Some(t) = queue.pop() {
        queued[t as usize] = false;
        if mesh.corners(t)[0] == NONE {
            continue;
        }
        for j in 0..3 {
            let Some((u, quad)) = mesh.quad(t, j) else {
                continue;
            };
            let points = quad.map(|v| mesh.point(v));
            let [pa, pb, pc, pd] = &points;
            if spanned(pc, pd) >= spanned(pa, pb) || !flip_within(mesh, rules, t, j, &points, limit)
            {
                continue;
            }
            flips += 1;
            for w in [
                t,
                u,
                mesh.across(t, 0),
                mesh.across(t, 1),
                mesh.across(u, 1),
                mesh.across(u, 2),
            ] {
                if w != NONE && !queued[w as usize] {
                    queued[w as usize] = true;
                    queue.push(w);
                }
            }
            break;
        }
    }
    flips
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_the_levels_in_the_half_open_range() {
        let levels = [0.0, 10.0, 20.0, 30.0];
        assert_eq!(levels_spanned(&levels, 5.0, 25.0), 2);
        assert_eq!(levels_spanned(&levels, 10.0, 20.0), 1);
        assert_eq!(levels_spanned(&levels, 10.0, 10.0), 0);
        assert_eq!(levels_spanned(&levels, -5.0, 35.0), 4);
        assert_eq!(levels_spanned(&levels, 31.0, 35.0), 0);
    }
}
