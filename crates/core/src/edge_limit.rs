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

/// An edge length limit made ready to test edges with: the same test, bit for bit, for the
/// decimation and for a caller deciding a tile's border by it.
#[derive(Debug, Clone)]
pub struct EdgeLimit {
    /// For [`EdgeMetric::Sphere`].
    sphere: Option<SphereTables>,
    /// The largest [`EdgeLimit::measure`] allowed (infinite without a limit).
    max: f64,
}

/// `(cos, sin)` of each column's longitude and of each row's latitude.
#[derive(Debug, Clone)]
struct SphereTables {
    columns: Arc<[[f64; 2]]>,
    rows: Arc<[[f64; 2]]>,
}

/// No limit.
pub(crate) static NO_EDGE_LIMIT: EdgeLimit = EdgeLimit {
    sphere: None,
    max: f64::INFINITY,
};

impl EdgeLimit {
    /// Edges of at most `max_edge_length` spacings by `metric`, on a grid `width` x
    /// `height` samples; no limit for `None`.
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
        let Some(length) = max_edge_length else {
            return Ok(NO_EDGE_LIMIT.clone());
        };
        if length < 2 {
            return Err(Error::InvalidMaxEdgeLength(length));
        }
        match metric {
            EdgeMetric::Grid => Ok(EdgeLimit {
                sphere: None,
                max: f64::from(length) * f64::from(length),
            }),
            EdgeMetric::Sphere {
                longitudes,
                latitudes,
                spacing,
            } => {
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
                        "a longitude, latitude or the spacing is not a finite number".into(),
                    ));
                }
                let arc = f64::from(length) * spacing.to_radians();
                let trig = |degrees: &[f64]| -> Arc<[[f64; 2]]> {
                    degrees
                        .iter()
                        .map(|d| {
                            let r = d.to_radians();
                            [r.cos(), r.sin()]
                        })
                        .collect()
                };
                Ok(EdgeLimit {
                    sphere: Some(SphereTables {
                        columns: trig(longitudes),
                        rows: trig(latitudes),
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

    /// Whether there is no limit.
    pub(crate) fn is_none(&self) -> bool {
        self.max == f64::INFINITY
    }

    /// A measure of segment `pq`'s length that grows with it: its squared length in
    /// spacings on the grid, `1 - cos` of its arc on a sphere.
    #[inline]
    pub(crate) fn measure(&self, p: &Point, q: &Point) -> f64 {
        match &self.sphere {
            None => {
                let (dx, dy) = (p.x - q.x, p.y - q.y);
                (dx * dx + dy * dy) as f64
            }
            Some(SphereTables { columns, rows }) => {
                let ([cl1, sl1], [cl2, sl2]) = (columns[p.x as usize], columns[q.x as usize]);
                let ([cp1, sp1], [cp2, sp2]) = (rows[p.y as usize], rows[q.y as usize]);
                1.0 - (cp1 * cp2 * (cl1 * cl2 + sl1 * sl2) + sp1 * sp2)
            }
        }
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

    /// Whether the segment between samples `(x, y)` of `a` and `b` is within the limit.
    pub fn allows_samples(&self, a: (u32, u32), b: (u32, u32)) -> bool {
        let point = |(x, y): (u32, u32)| Point {
            x: i64::from(x),
            y: i64::from(y),
            z: 0.0,
        };
        self.allows(&point(a), &point(b))
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
        // Along a meridian a spacing is a spacing of arc everywhere.
        assert!(limit.allows_samples((5, 61), (5, 70)));
        assert!(!limit.allows_samples((5, 61), (5, 72)));
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
