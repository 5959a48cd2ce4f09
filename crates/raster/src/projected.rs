//! A lattice block's positions in a projected raster's CRS: PROJ transforms the nodes of a
//! global grid of every [`NODE_STEP`]-th lattice column and row, and the points between
//! are interpolated bilinearly in longitude and latitude wherever that is as good as PROJ
//! to [`NODE_TOLERANCE`] of a pixel (checked at each node cell's centre); elsewhere each
//! point is transformed on its own.
//!
//! On Big Tujunga's pyramid (UTM, levels 0-12) PROJ and the trigonometry it calls were
//! about 28 % of the run (`perf record`); interpolating leaves one PROJ call for about
//! every 32 points.
//!
//! # Guarantees
//! A point's position depends only on the lattice and its global column and row: the node
//! cell holding it is the one whose south-west node is at or below it in both, whatever
//! block it is sampled in, and whether that cell is interpolated depends on its nodes and
//! centre alone.

use std::ops::Range;

use gdal::spatial_ref::CoordTransform;

use crate::geographic::GeoLattice;

/// Lattice points between the nodes PROJ transforms, each way.
pub(crate) const NODE_STEP: u64 = 8;

/// The largest difference, in pixels, between a node cell's interpolated centre and PROJ's
/// for the cell to be interpolated: on a raster of 30 m pixels, 3 mm (GDAL's warper allows
/// 0.125 pixels by default). Big Tujunga's UTM cells at level 12 are within 1.01e-5 (the
/// error grows with the square of the cell's size, so 0.6 km pixels interpolate to about
/// 2e-4 and are transformed point by point).
pub(crate) const NODE_TOLERANCE: f64 = 1e-4;

/// The positions in the raster's CRS (x, y; infinite or NaN where PROJ cannot transform)
/// of lattice columns `columns`, rows `rows`, row-major into `xs`, `ys` (cleared first).
/// `pixels` takes a displacement in the CRS to its length in pixels (the larger of its
/// column and row parts).
pub(crate) fn project_block(
    transform: &CoordTransform,
    lattice: &GeoLattice,
    (columns, rows): (Range<u32>, Range<u32>),
    pixels: &dyn Fn(f64, f64) -> f64,
    xs: &mut Vec<f64>,
    ys: &mut Vec<f64>,
) {
    let k = NODE_STEP;
    xs.clear();
    ys.clear();
    if !nodes_repeat_each_turn(lattice) {
        // A point a turn east would fall in other node cells: each point alone.
        for j in rows {
            let lat = lattice.lat(j);
            for i in columns.clone() {
                xs.push(lattice.lon(i));
                ys.push(lat);
            }
        }
        let _ = transform.transform_coords(xs, ys, &mut []);
        return;
    }
    let global_column = |i: u32| lattice.first_column + u64::from(i);
    let global_row = |j: u32| lattice.first_row + u64::from(j);
    // The node cells holding the block: from the one at or below its first point to the
    // one at or below its last, each with its far nodes.
    let (c0, r0) = (global_column(columns.start) / k, global_row(rows.start) / k);
    let cells_wide = (global_column(columns.end - 1) / k - c0 + 1) as usize;
    let cells_high = (global_row(rows.end - 1) / k - r0 + 1) as usize;
    // Global column `c` of the lattice as one whose first column is `c0 * k`.
    let at = GeoLattice {
        first_column: c0 * k,
        first_row: r0 * k,
        ..*lattice
    };
    let node_lon = |a: usize| at.lon((a as u64 * k) as u32);
    let node_lat = |b: usize| at.lat((b as u64 * k) as u32);
    let half = (k / 2) as u32;

    // Nodes, then cell centres, in one call to PROJ.
    let (nodes_wide, nodes_high) = (cells_wide + 1, cells_high + 1);
    let mut px = Vec::with_capacity(nodes_wide * nodes_high + cells_wide * cells_high);
    let mut py = Vec::with_capacity(px.capacity());
    for b in 0..nodes_high {
        for a in 0..nodes_wide {
            px.push(node_lon(a));
            py.push(node_lat(b));
        }
    }
    for b in 0..cells_high {
        for a in 0..cells_wide {
            px.push(at.lon((a as u64 * k) as u32 + half));
            py.push(at.lat((b as u64 * k) as u32 + half));
        }
    }
    // A point PROJ cannot transform comes back infinite (the call's error is for those).
    let _ = transform.transform_coords(&mut px, &mut py, &mut []);
    let node = |a: usize, b: usize| (px[b * nodes_wide + a], py[b * nodes_wide + a]);
    let centre = |a: usize, b: usize| {
        let n = nodes_wide * nodes_high + b * cells_wide + a;
        (px[n], py[n])
    };

    // Whether each cell is interpolated: its nodes and centre transformed, no turn of
    // longitude inside it, and its interpolated centre within the tolerance of PROJ's.
    let cell_step = k as f64 * lattice.step;
    let interpolated: Vec<bool> = (0..cells_high)
        .flat_map(|b| (0..cells_wide).map(move |a| (a, b)))
        .map(|(a, b)| {
            let corners = [
                node(a, b),
                node(a + 1, b),
                node(a, b + 1),
                node(a + 1, b + 1),
            ];
            let (cx, cy) = centre(a, b);
            let finite = corners.iter().all(|(x, y)| x.is_finite() && y.is_finite())
                && cx.is_finite()
                && cy.is_finite();
            let no_turn = (node_lon(a + 1) - node_lon(a) - cell_step).abs() <= 1e-9 * cell_step;
            if !(finite && no_turn) {
                return false;
            }
            let (lat0, lat1) = (node_lat(b), node_lat(b + 1));
            let s = (at.lat((b as u64 * k) as u32 + half) - lat0) / (lat1 - lat0);
            let (ix, iy) = bilinear(corners, 0.5, s);
            pixels(ix - cx, iy - cy) <= NODE_TOLERANCE
        })
        .collect();

    let mut exact = Vec::new();
    for j in rows.clone() {
        let row = global_row(j);
        let b = (row / k - r0) as usize;
        let lat = lattice.lat(j);
        let (lat0, lat1) = (node_lat(b), node_lat(b + 1));
        let s = (lat - lat0) / (lat1 - lat0);
        for i in columns.clone() {
            let column = global_column(i);
            let a = (column / k - c0) as usize;
            if interpolated[b * cells_wide + a] {
                let t = (column % k) as f64 / k as f64;
                let corners = [
                    node(a, b),
                    node(a + 1, b),
                    node(a, b + 1),
                    node(a + 1, b + 1),
                ];
                let (x, y) = bilinear(corners, t, s);
                xs.push(x);
                ys.push(y);
            } else {
                exact.push(xs.len());
                xs.push(lattice.lon(i));
                ys.push(lat);
            }
        }
    }
    if !exact.is_empty() {
        let mut ex: Vec<f64> = exact.iter().map(|&n| xs[n]).collect();
        let mut ey: Vec<f64> = exact.iter().map(|&n| ys[n]).collect();
        let _ = transform.transform_coords(&mut ex, &mut ey, &mut []);
        for ((&n, x), y) in exact.iter().zip(ex).zip(ey) {
            (xs[n], ys[n]) = (x, y);
        }
    }
}

/// Whether the node grid is the same a turn east: [`GeoLattice::lon`] counts columns
/// modulo a turn when a turn is a whole number of steps, so a point has two global columns
/// a turn apart, which fall in node cells of the same positions only when the turn is a
/// whole number of cells (every level but the coarsest two or three: a turn is 2^(z+1) or
/// 2^z times the tile's cells).
fn nodes_repeat_each_turn(lattice: &GeoLattice) -> bool {
    let turn = (360.0 / lattice.step).round();
    let whole = turn >= 1.0 && (turn * lattice.step - 360.0).abs() <= 1e-9;
    !whole || (turn as u64).is_multiple_of(NODE_STEP)
}

/// The bilinear interpolation of `corners` (south-west, south-east, north-west,
/// north-east) at `t` of the way east and `s` of the way north: at `t` or `s` of 0 or 1,
/// exactly the corners' values on that side.
fn bilinear(corners: [(f64, f64); 4], t: f64, s: f64) -> (f64, f64) {
    let lerp = |p: f64, q: f64, w: f64| (1.0 - w) * p + w * q;
    let [sw, se, nw, ne] = corners;
    let south = (lerp(sw.0, se.0, t), lerp(sw.1, se.1, t));
    let north = (lerp(nw.0, ne.0, t), lerp(nw.1, ne.1, t));
    (lerp(south.0, north.0, s), lerp(south.1, north.1, s))
}

#[cfg(test)]
mod tests {
    use gdal::spatial_ref::SpatialRef;

    use super::*;
    use crate::geographic::{wgs84, Latitudes};

    /// WGS84 to UTM zone 11N, and the length in 30 m pixels of a displacement.
    fn utm() -> (CoordTransform, impl Fn(f64, f64) -> f64) {
        let utm = SpatialRef::from_epsg(32611).expect("EPSG:32611");
        let transform = CoordTransform::new(&wgs84().expect("WGS84"), &utm).expect("PROJ");
        (transform, |dx: f64, dy: f64| dx.abs().max(dy.abs()) / 30.0)
    }

    /// About Big Tujunga at level 12 of the geographic tiling (22 m spacing), and at
    /// level 6 (1.4 km), where the node cells are too large to interpolate.
    fn lattice(level: u32, first_column: u64, first_row: u64) -> GeoLattice {
        let step = 180.0 / (217.0 * f64::from(1u32 << level));
        GeoLattice {
            west: -180.0,
            south: -90.0,
            step,
            first_column: first_column + ((180.0 - 118.3) / step) as u64,
            first_row: first_row + ((90.0 + 34.2) / step) as u64,
            width: 64,
            height: 64,
            latitudes: Latitudes::Uniform,
        }
    }

    fn exact(transform: &CoordTransform, lattice: &GeoLattice) -> (Vec<f64>, Vec<f64>) {
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for j in 0..lattice.height {
            for i in 0..lattice.width {
                xs.push(lattice.lon(i));
                ys.push(lattice.lat(j));
            }
        }
        transform
            .transform_coords(&mut xs, &mut ys, &mut [])
            .expect("PROJ");
        (xs, ys)
    }

    #[test]
    fn interpolated_positions_are_within_the_tolerance_of_projs() {
        let (transform, pixels) = utm();
        for (level, interpolates) in [(12, true), (6, false)] {
            let lattice = lattice(level, 3, 5);
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            let block = (0..lattice.width, 0..lattice.height);
            project_block(&transform, &lattice, block, &pixels, &mut xs, &mut ys);
            let (ex, ey) = exact(&transform, &lattice);
            let worst = (0..xs.len())
                .map(|n| pixels(xs[n] - ex[n], ys[n] - ey[n]))
                .fold(0.0f64, f64::max);
            let differ = (0..xs.len())
                .filter(|&n| (xs[n], ys[n]) != (ex[n], ey[n]))
                .count();
            assert!(
                worst <= 2.0 * NODE_TOLERANCE,
                "level {level}: {worst} pixels"
            );
            assert_eq!(
                differ > xs.len() / 2,
                interpolates,
                "level {level}: {differ}"
            );
        }
    }

    #[test]
    fn a_point_a_turn_east_gets_the_same_position() {
        // NAD83 longitude, latitude: nearly WGS84's, so cells interpolate at any size.
        let mut nad83 = SpatialRef::from_epsg(4269).expect("EPSG:4269");
        nad83
            .set_axis_mapping_strategy(gdal::spatial_ref::AxisMappingStrategy::TraditionalGisOrder);
        let transform = CoordTransform::new(&wgs84().expect("WGS84"), &nad83).expect("PROJ");
        let pixels = |dx: f64, dy: f64| dx.abs().max(dy.abs()) / 0.01;
        // Levels 0 (a turn of 434 columns, not a whole number of node cells) to 3.
        for level in 0..4 {
            let step = 180.0 / (217.0 * f64::from(1u32 << level));
            let turn = (360.0 / step).round() as u64;
            let window = |first_column: u64| GeoLattice {
                west: -180.0,
                south: -90.0,
                step,
                first_column,
                first_row: 10,
                width: 37,
                height: 21,
                latitudes: Latitudes::Uniform,
            };
            let (mut ax, mut ay, mut bx, mut by) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let block = (0..37, 0..21);
            project_block(
                &transform,
                &window(turn - 20),
                block.clone(),
                &pixels,
                &mut ax,
                &mut ay,
            );
            project_block(
                &transform,
                &window(2 * turn - 20),
                block,
                &pixels,
                &mut bx,
                &mut by,
            );
            assert_eq!((ax, ay), (bx, by), "level {level}");
        }
    }

    #[test]
    fn a_point_gets_the_same_position_in_any_block() {
        let (transform, pixels) = utm();
        let whole = lattice(12, 0, 0);
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        let block = (0..whole.width, 0..whole.height);
        project_block(&transform, &whole, block, &pixels, &mut xs, &mut ys);
        for (i0, j0, i1, j1) in [
            (0, 0, 64, 64),
            (3, 5, 17, 40),
            (8, 8, 9, 9),
            (13, 0, 64, 31),
        ] {
            let (mut bx, mut by) = (Vec::new(), Vec::new());
            project_block(
                &transform,
                &whole,
                (i0..i1, j0..j1),
                &pixels,
                &mut bx,
                &mut by,
            );
            let mut n = 0;
            for j in j0..j1 {
                for i in i0..i1 {
                    let k = (j * whole.width + i) as usize;
                    assert_eq!(
                        (bx[n].to_bits(), by[n].to_bits()),
                        (xs[k].to_bits(), ys[k].to_bits()),
                        "point {i}, {j} in block {i0}..{i1} x {j0}..{j1}"
                    );
                    n += 1;
                }
            }
            // A window of a larger lattice: the same global points.
            let shifted = GeoLattice {
                first_column: whole.first_column + u64::from(i0),
                first_row: whole.first_row + u64::from(j0),
                width: i1 - i0,
                height: j1 - j0,
                ..whole
            };
            let (mut sx, mut sy) = (Vec::new(), Vec::new());
            let block = (0..shifted.width, 0..shifted.height);
            project_block(&transform, &shifted, block, &pixels, &mut sx, &mut sy);
            assert_eq!(sx, bx);
            assert_eq!(sy, by);
        }
    }
}
