//! The longest edge a decimation may make ([`crate::DecimationOptions::max_edge_length`]),
//! measured on the grid or, for a grid whose samples sit on a sphere, along it.

use std::sync::Arc;

use crate::predicates::Point;
use crate::{Error, Result};

/// How an edge's length is measured against
/// [`crate::DecimationOptions::max_edge_length`].
#[derive(Debug, Clone, PartialEq, Default)]
pub enum EdgeMetric {
    /// In sample spacings on the grid.
    #[default]
    Grid,
    /// As the great-circle arc between the two samples' positions on a sphere, in units of
    /// `spacing` degrees of arc: the grid's column `x` is at longitude `longitudes[x]` and
    /// its row `y` at latitude `latitudes[y]` (degrees). For a renderer that draws each
    /// triangle flat between points on a globe, where a chord sinks below the surface by
    /// what its arc spans, not by how many samples it crosses: towards the poles a row's
    /// samples draw together, and edges along it may cross more of them.
    Sphere {
        /// Per grid column, its longitude in degrees.
        longitudes: Arc<[f64]>,
        /// Per grid row, its latitude in degrees.
        latitudes: Arc<[f64]>,
        /// Degrees of arc counted as one spacing.
        spacing: f64,
    },
}

/// An edge length limit made ready to test edges with: the test the decimation makes, for
/// a caller to decide by it too (a tile's border skips).
#[derive(Debug, Clone)]
pub struct EdgeLimit {
    /// For [`EdgeMetric::Sphere`].
    sphere: Option<SphereTables>,
    /// The largest [`EdgeLimit::measure`] allowed (infinite without a limit).
    max: f64,
}

/// `(cos, sin, degrees)` of each column's longitude and `(cos, sin)` of each row's
/// latitude.
#[derive(Debug, Clone)]
struct SphereTables {
    columns: Arc<[[f64; 3]]>,
    rows: Arc<[[f64; 2]]>,
}

/// The triple product of unit vectors below which [`EdgeLimit::faces_out`] calls a
/// triangle turned over: far above its rounding where two corners coincide (a pole's row,
/// whose points differ by about 1e-16) and below a face of one lattice cell of the
/// finest level a pyramid caps (level 10 at `--quality` 0.1, 0.0008 degree a side: about
/// 2e-10).
const FACE_TOLERANCE: f64 = 1e-12;

/// No limit.
pub(crate) static NO_EDGE_LIMIT: EdgeLimit = EdgeLimit {
    sphere: None,
    max: f64::INFINITY,
};

impl EdgeLimit {
    /// Edges of at most `max_edge_length` spacings by `metric`, on a grid `width` x
    /// `height` samples; no length limit for `None`, though on a sphere triangles must
    /// still face outwards ([`EdgeLimit::faces_out_samples`]).
    ///
    /// # Errors
    /// [`Error::InvalidMaxEdgeLength`] below 2 spacings; [`Error::EdgeMetric`] when a
    /// sphere's longitudes or latitudes do not match the grid or a number is not finite.
    pub fn new(
        metric: &EdgeMetric,
        max_edge_length: Option<u32>,
        width: u32,
        height: u32,
    ) -> Result<EdgeLimit> {
        if let Some(length) = max_edge_length.filter(|&l| l < 2) {
            return Err(Error::InvalidMaxEdgeLength(length));
        }
        match (metric, max_edge_length) {
            (EdgeMetric::Grid, None) => Ok(NO_EDGE_LIMIT.clone()),
            (EdgeMetric::Grid, Some(length)) => Ok(EdgeLimit {
                sphere: None,
                max: f64::from(length) * f64::from(length),
            }),
            (
                EdgeMetric::Sphere {
                    longitudes,
                    latitudes,
                    spacing,
                },
                _,
            ) => {
                if longitudes.len() != width as usize || latitudes.len() != height as usize {
                    return Err(Error::EdgeMetric(format!(
                        "{} longitudes and {} latitudes for a grid of {width} x {height}",
                        longitudes.len(),
                        latitudes.len()
                    )));
                }
                let finite = longitudes
                    .iter()
                    .chain(latitudes.iter())
                    .all(|v| v.is_finite());
                if !finite || !spacing.is_finite() || *spacing <= 0.0 {
                    return Err(Error::EdgeMetric(
                        "a longitude, latitude or the spacing is not finite, or the spacing not positive"
                            .into(),
                    ));
                }
                let arc = max_edge_length.map_or(f64::INFINITY, |length| {
                    f64::from(length) * spacing.to_radians()
                });
                let trig = |d: f64| [d.to_radians().cos(), d.to_radians().sin()];
                Ok(EdgeLimit {
                    sphere: Some(SphereTables {
                        columns: longitudes
                            .iter()
                            .map(|&d| {
                                let [c, s] = trig(d);
                                [c, s, d]
                            })
                            .collect(),
                        rows: latitudes.iter().map(|&d| trig(d)).collect(),
                    }),
                    // 1 - cos(arc): the measure of an edge spanning `arc`; a half turn or
                    // more allows any edge.
                    max: if arc >= std::f64::consts::PI {
                        f64::INFINITY
                    } else {
                        1.0 - arc.cos()
                    },
                })
            }
        }
    }

    /// Whether there is no length limit (on a sphere, triangles must still face out).
    pub(crate) fn is_none(&self) -> bool {
        self.max == f64::INFINITY
    }

    /// Whether triangles may turn over as drawn ([`EdgeLimit::faces_out`] can refuse).
    pub(crate) fn on_sphere(&self) -> bool {
        self.sphere.is_some()
    }

    /// A measure of segment `pq`'s length that grows with it: its squared length in
    /// spacings on the grid, `1 - cos` of its arc on a sphere (infinite for a segment
    /// across half a turn of longitude or more, which the arc would take for the other
    /// way round).
    #[inline]
    pub(crate) fn measure(&self, p: &Point, q: &Point) -> f64 {
        match &self.sphere {
            None => {
                let (dx, dy) = (p.x - q.x, p.y - q.y);
                (dx * dx + dy * dy) as f64
            }
            Some(SphereTables { columns, rows }) => {
                let ([cl1, sl1, l1], [cl2, sl2, l2]) =
                    (columns[p.x as usize], columns[q.x as usize]);
                if (l1 - l2).abs() >= 180.0 {
                    return f64::INFINITY;
                }
                let ([cp1, sp1], [cp2, sp2]) = (rows[p.y as usize], rows[q.y as usize]);
                1.0 - (cp1 * cp2 * (cl1 * cl2 + sl1 * sl2) + sp1 * sp2)
            }
        }
    }

    /// Whether counter-clockwise triangle `abc` (grid positions) faces outwards where it
    /// is drawn flat between its corners' positions: always on the grid; on a sphere,
    /// unless its corners' triple product is negative (beyond rounding). Edges within the
    /// arc alone do not ensure it: near a pole, a corner can sit between the chord of a
    /// long edge along a row and the row itself. A triangle with two corners at one point
    /// (a pole's row) has no face and passes.
    pub(crate) fn faces_out(&self, a: &Point, b: &Point, c: &Point) -> bool {
        let Some(SphereTables { columns, rows }) = &self.sphere else {
            return true;
        };
        let unit = |p: &Point| {
            let ([cl, sl, _], [cp, sp]) = (columns[p.x as usize], rows[p.y as usize]);
            [cp * cl, cp * sl, sp]
        };
        let (a, b, c) = (unit(a), unit(b), unit(c));
        let cross = [
            b[1] * c[2] - b[2] * c[1],
            b[2] * c[0] - b[0] * c[2],
            b[0] * c[1] - b[1] * c[0],
        ];
        a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2] > -FACE_TOLERANCE
    }

    /// Whether a measure ([`EdgeLimit::measure`]) is within the limit.
    #[inline]
    pub(crate) fn allows_measure(&self, measure: f64) -> bool {
        measure <= self.max
    }

    /// Whether segment `pq` (grid positions) is within the limit.
    #[inline]
    pub(crate) fn allows(&self, p: &Point, q: &Point) -> bool {
        self.is_none() || self.allows_measure(self.measure(p, q))
    }

    /// Whether the triangle of samples `(x, y)` `a`, `b`, `c`, counter-clockwise on the
    /// grid, faces outwards where it is drawn flat between its corners' positions: always
    /// on the grid; on a sphere, unless its corners' triple product is negative (beyond
    /// rounding; two corners at one point, a pole's row, pass).
    ///
    /// # Panics
    /// On a sphere, when a sample is outside the grid the limit was made for.
    pub fn faces_out_samples(&self, a: (u32, u32), b: (u32, u32), c: (u32, u32)) -> bool {
        self.faces_out(&sample_point(a), &sample_point(b), &sample_point(c))
    }

    /// Whether the segment between samples `(x, y)` of `a` and `b` is within the limit.
    ///
    /// # Panics
    /// On a sphere, when a sample is outside the grid the limit was made for.
    pub fn allows_samples(&self, a: (u32, u32), b: (u32, u32)) -> bool {
        self.allows(&sample_point(a), &sample_point(b))
    }
}

/// Sample `(x, y)` as a grid position (its height unused here).
fn sample_point((x, y): (u32, u32)) -> Point {
    Point {
        x: i64::from(x),
        y: i64::from(y),
        z: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(width: usize, height: usize, step: f64, south: f64) -> EdgeMetric {
        EdgeMetric::Sphere {
            longitudes: (0..width).map(|x| x as f64 * step).collect(),
            latitudes: (0..height).map(|y| south + y as f64 * step).collect(),
            spacing: step,
        }
    }

    #[test]
    fn on_the_grid_the_length_is_in_spacings() {
        let limit = EdgeLimit::new(&EdgeMetric::Grid, Some(5), 20, 20).unwrap();
        assert!(limit.allows_samples((0, 0), (3, 4)));
        assert!(!limit.allows_samples((0, 0), (4, 4)));
        assert!(EdgeLimit::new(&EdgeMetric::Grid, None, 20, 20)
            .unwrap()
            .allows_samples((0, 0), (19, 19)));
    }

    #[test]
    fn on_the_sphere_rows_near_a_pole_allow_more_samples() {
        // At the equator a row's spacing is one spacing of arc; at 60 degrees about half.
        let metric = sphere(40, 91, 1.0, -1.0);
        let limit = EdgeLimit::new(&metric, Some(10), 40, 91).unwrap();
        assert!(limit.allows_samples((0, 1), (9, 1)));
        assert!(!limit.allows_samples((0, 1), (11, 1)));
        assert!(limit.allows_samples((0, 61), (19, 61)));
        assert!(!limit.allows_samples((0, 61), (21, 61)));
        // Half a turn of longitude or more is refused, even where it spans little arc.
        let near_pole = EdgeMetric::Sphere {
            longitudes: vec![0.0, 100.0, 200.0].into(),
            latitudes: vec![89.0, 89.5].into(),
            spacing: 1.0,
        };
        let wide = EdgeLimit::new(&near_pole, Some(4), 3, 2).unwrap();
        assert!(wide.allows_samples((0, 1), (1, 1)));
        assert!(!wide.allows_samples((0, 1), (2, 1)));
        // Along a meridian a spacing is a spacing of arc everywhere.
        assert!(limit.allows_samples((5, 61), (5, 70)));
        assert!(!limit.allows_samples((5, 61), (5, 72)));
    }

    #[test]
    fn a_triangle_turned_over_near_a_pole_is_refused_though_its_edges_fit() {
        // A (0, 80), B (100, 80), C (50, 80.83): every edge under 16 degrees of arc, and
        // counter-clockwise on the grid, but C lies between the chord AB and the row.
        let metric = EdgeMetric::Sphere {
            longitudes: vec![0.0, 50.0, 100.0].into(),
            latitudes: vec![80.0, 80.83].into(),
            spacing: 1.0,
        };
        let limit = EdgeLimit::new(&metric, Some(16), 3, 2).unwrap();
        let p = |x, y| Point { x, y, z: 0.0 };
        let (a, b, c) = (p(0, 0), p(2, 0), p(1, 1));
        assert!(limit.allows(&a, &b) && limit.allows(&b, &c) && limit.allows(&c, &a));
        assert!(!limit.faces_out(&a, &b, &c));
        assert!(limit.faces_out(&a, &p(1, 0), &p(0, 1)));
        // On the grid every counter-clockwise triangle faces out.
        let grid = EdgeLimit::new(&EdgeMetric::Grid, Some(16), 3, 2).unwrap();
        assert!(grid.faces_out(&a, &b, &c));
    }

    #[test]
    fn a_sphere_that_does_not_fit_the_grid_is_refused() {
        let metric = sphere(10, 10, 1.0, 0.0);
        assert!(matches!(
            EdgeLimit::new(&metric, Some(4), 11, 10),
            Err(Error::EdgeMetric(_))
        ));
        assert!(matches!(
            EdgeLimit::new(&metric, Some(1), 10, 10),
            Err(Error::InvalidMaxEdgeLength(1))
        ));
    }
}
