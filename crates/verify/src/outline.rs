//! Which points a TIN with a given outline must cover: those inside its rings (even-odd:
//! an outline and its holes), with its own `f64` test.

/// For each point `[x, y, ..]`, whether it is inside the `rings` (closed, world `[x, y]`;
/// even-odd, so holes are outside) or within `tolerance` of a ring's edge (a boundary
/// point, kept by `mesh --boundary`, whose vertices are rounded to a lattice).
pub fn inside_outline(rings: &[Vec<[f64; 2]>], points: &[[f64; 3]], tolerance: f64) -> Vec<bool> {
    points
        .iter()
        .map(|p| {
            let mut inside = false;
            for ring in rings {
                for w in ring.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    if near_segment(a, b, [p[0], p[1]], tolerance) {
                        return true;
                    }
                    if (a[1] > p[1]) != (b[1] > p[1]) {
                        let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                        if x > p[0] {
                            inside = !inside;
                        }
                    }
                }
            }
            inside
        })
        .collect()
}

fn near_segment(a: [f64; 2], b: [f64; 2], p: [f64; 2], tolerance: f64) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let length2 = d[0] * d[0] + d[1] * d[1];
    let t = if length2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + t * d[0], a[1] + t * d[1]];
    (p[0] - q[0]).hypot(p[1] - q[1]) <= tolerance
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holes_are_outside_and_the_outline_inside() {
        let square = |a: f64, b: f64| vec![[a, a], [b, a], [b, b], [a, b], [a, a]];
        let rings = vec![square(0.0, 10.0), square(4.0, 6.0)];
        let points = [
            [1.0, 1.0, 0.0],
            [5.0, 5.0, 0.0],
            [11.0, 5.0, 0.0],
            [10.0, 5.0, 0.0],
            [10.001, 5.0, 0.0],
        ];
        assert_eq!(
            inside_outline(&rings, &points, 0.0),
            [true, false, false, true, false]
        );
        assert_eq!(
            inside_outline(&rings, &points, 0.01),
            [true, false, false, true, true]
        );
    }
}
