//! A tile's edges measured on the globe. CesiumJS draws each triangle flat between its
//! corners, so on a coarse level an edge may span no more arc than the level's bound lets
//! its chord sink ([`crate::tms::max_edge_length`], in lattice spacings at the equator).
//! Measured along the sphere instead of across the lattice, a tile's rows draw together
//! towards the poles, and edges along them may cross more lattice points. On every level,
//! capped or not, no triangle may turn over as drawn: a long edge along a row bulges
//! poleward, past a thin triangle's third corner.

use tinsmith_core::{EdgeLimit, EdgeMetric};

use crate::tms::Scheme;

/// A tile's edge metric and the longest skip between kept samples on each of its four
/// edges.
pub(super) struct GlobeEdges {
    /// The metric of the tile's lattice, for its decimation.
    pub(super) metric: EdgeMetric,
    /// South, north, west and east: the longest skip, in samples, between kept samples
    /// of the edge such that every edge of the border fans is within the limit, on both
    /// sides of the edge (so both tiles beside it compute the same).
    pub(super) spans: [usize; 4],
}

/// Relative tightening of the arc the border spans are decided with, so that the fans
/// the span allows (which the core makes without measuring them) stay within the tile's
/// own limit whatever the rounding of their lattice against the tile's.
const SPAN_MARGIN: f64 = 1e-9;

/// The globe edges of tile `z`/`column`/`y` of `scheme` whose edges may span at most
/// `max_edge` lattice spacings of arc at the equator (any length for `None`).
pub(super) fn globe_edges(
    scheme: Scheme,
    z: u8,
    column: u32,
    y: u32,
    max_edge: Option<u32>,
) -> GlobeEdges {
    let cells = scheme.cells as usize;
    let step = scheme.step(z);
    let rect = scheme.tile_rectangle(z, column, y);
    let d_lat = row_spacing(scheme, z, column, y);
    let longitudes: Vec<f64> = (0..=cells).map(|i| i as f64 * step).collect();
    let latitudes: Vec<f64> = (0..=cells).map(|j| rect.south + j as f64 * d_lat).collect();
    let metric = EdgeMetric::Sphere {
        longitudes: longitudes.clone().into(),
        latitudes: latitudes.clone().into(),
        spacing: step,
    };
    let rows = 1u32 << z;
    // A parallel edge at `lat`, with the rows beside it: `below` and `above` spacings
    // where a tile lies there.
    let parallel = |lat: f64, below: Option<f64>, above: Option<f64>| {
        let beside = [below.map(|d| lat - d), Some(lat), above.map(|d| lat + d)];
        span(step, max_edge, &longitudes, &beside, true)
    };
    // A meridian edge: the columns beside it are one step away on both sides.
    let meridian = || {
        let beside = [Some(-step), Some(0.0), Some(step)];
        span(step, max_edge, &latitudes, &beside, false)
    };
    let neighbour = |dy: i64| {
        let y = i64::from(y) + dy;
        (0..i64::from(rows))
            .contains(&y)
            .then(|| row_spacing(scheme, z, column, y as u32))
    };
    let south = parallel(rect.south, neighbour(-1), Some(d_lat));
    let north = parallel(rect.north, Some(d_lat), neighbour(1));
    let west_east = meridian();
    GlobeEdges {
        metric,
        spans: [south, north, west_east, west_east],
    }
}

/// The latitude between a tile's rows (evenly spaced inside it, as CesiumJS places `v`).
fn row_spacing(scheme: Scheme, z: u8, column: u32, y: u32) -> f64 {
    let rect = scheme.tile_rectangle(z, column, y);
    (rect.north - rect.south) / f64::from(scheme.cells)
}

/// The longest skip `s` along an edge of samples at `along` (degrees: longitudes of a
/// parallel edge, relative to its first; latitudes of a meridian edge) such that, from
/// every sample `i`, the segment to `i + s` and the fan edges to the samples `i` and
/// `i + s` of each line beside the edge that exists are within `max_edge` spacings of
/// `step` degrees (less [`SPAN_MARGIN`]; any length for `None`), and the core's fan
/// triangles on that line face outwards as drawn (a chord along a row bulges poleward,
/// past the next row where the skip is long); `usize::MAX` when every skip fits.
/// `beside` holds the three lines' positions across the edge (latitudes, or
/// longitudes), the edge's own in the middle.
fn span(
    step: f64,
    max_edge: Option<u32>,
    along: &[f64],
    beside: &[Option<f64>; 3],
    parallel: bool,
) -> usize {
    let n = along.len() - 1;
    let across: Vec<f64> = beside.iter().map(|b| b.unwrap_or(0.0)).collect();
    let (longitudes, latitudes) = if parallel {
        (along.to_vec(), across)
    } else {
        (across, along.to_vec())
    };
    let metric = EdgeMetric::Sphere {
        longitudes: longitudes.into(),
        latitudes: latitudes.into(),
        spacing: step * (1.0 - SPAN_MARGIN),
    };
    let (w, h) = if parallel { (n + 1, 3) } else { (3, n + 1) };
    let limit = EdgeLimit::new(&metric, max_edge, w as u32, h as u32)
        .expect("a lattice of finite positions");
    let at = |i: usize, line: usize| {
        if parallel {
            (i as u32, line as u32)
        } else {
            (line as u32, i as u32)
        }
    };
    let sides: Vec<usize> = [0, 2]
        .into_iter()
        .filter(|&l| beside[l].is_some())
        .collect();
    // The core removes a skipped border sample as a fan from the kept sample before it
    // (`p`, at `i`): `p` ends up joined to every sample `i..=i + s` of the line inside,
    // and to `q` at `i + s`. A fan triangle `p`, inside `k`, inside `k + 1` (or its last,
    // `p`, inside `k`, `q`), taken counter-clockwise, must face outwards as drawn.
    let fan_faces_out = |i: usize, s: usize, l: usize| {
        let p = at(i, 1);
        // Line 2 lies north (parallel) or east (meridian) of the edge.
        let ccw = |b: (u32, u32), c: (u32, u32), flipped: bool| {
            if flipped {
                limit.faces_out_samples(p, c, b)
            } else {
                limit.faces_out_samples(p, b, c)
            }
        };
        let flipped = (l == 2) == parallel;
        // Turned over, if at all, first at the far end: a chord along a row bulges most
        // at its middle, and the fan's last thin triangle straddles the skip's far half.
        let k = i + s - 1;
        ccw(at(k, l), at(k + 1, l), flipped)
            && [k, k + 1]
                .into_iter()
                .all(|k| ccw(at(k, l), at(i + s, 1), flipped))
    };
    let fits = |s: usize| {
        (0..=n - s).all(|i| {
            limit.allows_samples(at(i, 1), at(i + s, 1))
                && sides.iter().all(|&l| {
                    limit.allows_samples(at(i, 1), at(i + s, l))
                        && limit.allows_samples(at(i + s, 1), at(i, l))
                        && fan_faces_out(i, s, l)
                })
        })
    };
    // Arcs grow with the skip up to half a turn of longitude, and the limit refuses
    // anything wider: the skips that fit are 1..=s. Search for s.
    let (mut lo, mut hi) = (1, n);
    if fits(hi) {
        return usize::MAX;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::LevelBudget;
    use crate::tms::{Tiling, LATTICE_CELLS};

    fn schemes() -> Vec<Scheme> {
        LATTICE_CELLS
            .into_iter()
            .flat_map(|cells| {
                [Tiling::Geographic, Tiling::Mercator].map(|tiling| Scheme { tiling, cells })
            })
            .collect()
    }

    /// Levels 0 to 11 of `scheme` with their longest edge (`None` past the cap), at two
    /// `--quality`s.
    fn levels(scheme: Scheme) -> Vec<(u8, Option<u32>)> {
        [0.1, 1.0]
            .into_iter()
            .flat_map(|quality| {
                (0..12).map(move |z| (z, LevelBudget::new(scheme, z, quality).max_edge))
            })
            .collect()
    }

    #[test]
    fn both_tiles_beside_an_edge_decide_the_same_span() {
        for scheme in schemes() {
            for (z, max_edge) in levels(scheme) {
                let column = 0;
                // Every row up to level 5, then 32 spread from pole to pole.
                let rows = 1u32 << z;
                for y in (1..rows).step_by((rows as usize / 32).max(1)) {
                    let below = globe_edges(scheme, z, column, y - 1, max_edge);
                    let above = globe_edges(scheme, z, column, y, max_edge);
                    assert_eq!(below.spans[1], above.spans[0], "{scheme:?} {z}/{y}");
                    // West and east neighbours share a meridian edge.
                    let east = globe_edges(scheme, z, column + 1, y, max_edge);
                    assert_eq!(above.spans[3], east.spans[2]);
                }
            }
        }
    }

    #[test]
    fn every_fan_edge_of_a_span_is_within_the_tiles_own_limit() {
        for scheme in schemes() {
            let n = scheme.cells;
            for (z, max_edge) in levels(scheme) {
                // Every row up to level 5, then 32 spread from pole to pole.
                let rows = 1u32 << z;
                for y in (0..rows).step_by((rows as usize / 32).max(1)) {
                    let g = globe_edges(scheme, z, 0, y, max_edge);
                    let limit = EdgeLimit::new(&g.metric, max_edge, n + 1, n + 1).unwrap();
                    // Each edge (its line, and the line inside it) with its span.
                    let cases = [(g.spans[0], 0, 1, true), (g.spans[1], n, n - 1, true)]
                        .into_iter()
                        .chain([(g.spans[2], 0, 1, false), (g.spans[3], n, n - 1, false)]);
                    for (span, line, inner, along_rows) in cases {
                        let at = |i: u32, l: u32| if along_rows { (i, l) } else { (l, i) };
                        let s = span.min(n as usize) as u32;
                        for i in 0..=n - s {
                            assert!(limit.allows_samples(at(i, line), at(i + s, line)));
                            assert!(limit.allows_samples(at(i, line), at(i + s, inner)));
                            assert!(limit.allows_samples(at(i + s, line), at(i, inner)));
                            // Every triangle of the core's fan from `p` (the border
                            // sample first along the border) faces outwards: `p` to each
                            // pair of inner samples of the skip, and to its last inner
                            // sample and `q`; each taken counter-clockwise on the lattice.
                            let (p, q) = (at(i, line), at(i + s, line));
                            let faces_out = |b: (u32, u32), c: (u32, u32)| {
                                let (dx1, dy1) = (b.0 as i64 - p.0 as i64, b.1 as i64 - p.1 as i64);
                                let (dx2, dy2) = (c.0 as i64 - p.0 as i64, c.1 as i64 - p.1 as i64);
                                if dx1 * dy2 - dy1 * dx2 > 0 {
                                    limit.faces_out_samples(p, b, c)
                                } else {
                                    limit.faces_out_samples(p, c, b)
                                }
                            };
                            for k in i..i + s {
                                assert!(faces_out(at(k, inner), at(k + 1, inner)));
                            }
                            for k in [i + s - 1, i + s] {
                                assert!(faces_out(at(k, inner), q));
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn at_the_equator_a_span_is_the_grids_towards_a_pole_longer_and_shorter_where_fans_turn() {
        let scheme = Scheme {
            tiling: Tiling::Geographic,
            cells: 217,
        };
        let (z, max_edge) = (2, LevelBudget::new(scheme, 2, 1.0).max_edge);
        assert!(max_edge.is_some(), "level 2 is capped");
        let grid_span = tinsmith_tiling::edge_span(max_edge);
        // Level 2 has rows 0..4 of 45 degrees: row 2 starts at the equator.
        let equator = globe_edges(scheme, z, 0, 2, max_edge);
        assert_eq!(equator.spans[0], grid_span);
        assert_eq!(
            equator.spans[2], grid_span,
            "meridians are the grid's everywhere"
        );
        let polar = globe_edges(scheme, z, 0, 3, max_edge);
        assert!(
            polar.spans[1] > 3 * grid_span,
            "{} at the pole",
            polar.spans[1]
        );
        // At 45 degrees the row inside lies poleward, and a long skip's fans would turn
        // over before its arc reaches the cap: the span is shorter than the grid's (whose
        // skips of 84 turned fans from the 34th sample on).
        let fans = polar.spans[0];
        assert!(fans > 1 && fans < grid_span, "{fans} at 45 degrees");
    }

    #[test]
    fn past_the_cap_fans_still_may_not_turn_over() {
        let scheme = Scheme {
            tiling: Tiling::Geographic,
            cells: 217,
        };
        // Level 7 at `--quality` 2 has no cap. Row 96 spans 45.0 to 46.4 degrees north,
        // and the row inside its south edge lies poleward: a skip across the whole tile
        // would bulge its chord past the thin fans beside it.
        let z = 7;
        assert_eq!(LevelBudget::new(scheme, z, 2.0).max_edge, None, "no cap");
        let north = globe_edges(scheme, z, 0, 96, None);
        assert!(
            north.spans[0] > 1 && north.spans[0] < 217,
            "{:?}",
            north.spans
        );
        // Along meridians nothing bulges: any skip.
        assert_eq!(north.spans[2..], [usize::MAX; 2], "{:?}", north.spans);
        // Near the equator nothing turns over either.
        let equator = globe_edges(scheme, z, 0, 64, None);
        assert_eq!(equator.spans, [usize::MAX; 4]);
    }
}
