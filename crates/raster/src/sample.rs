//! A band's samples on a longitude/latitude lattice: each point on its own, transformed
//! exactly to the raster's pixel coordinates and interpolated bilinearly between the four
//! pixel centres around it, so that a point's sample depends only on the raster and its
//! position, never on the other points sampled with it.

use std::path::Path;

use gdal::raster::RasterBand;
use gdal::spatial_ref::{CoordTransform, CoordTransformOptions};

use crate::bilinear::{Footprint, PixelGrid, Window};
use crate::datum::{Geoid, VerticalDatum};
use crate::error::Result;
use crate::geographic::{
    area_of_interest, corner_box, geo_transform, source_crs, warp_error, wgs84, GeoLattice,
};
use crate::projected::project_block;
use crate::read::OpenBand;

/// Lattice points a side of the blocks the lattice is sampled in: the points of one block
/// are transformed in one call to PROJ and read from one window of the raster (or a few).
const BLOCK: u32 = 64;

/// Pixels a window may always hold (512 KiB of `f64`).
const MIN_WINDOW: usize = 1 << 16;

/// Pixels per point a window may hold beyond [`MIN_WINDOW`]: a group of points spread
/// wider is split in two, down to single points (four pixels each), so that a lattice far
/// coarser than the raster reads only the pixels around its points.
const PIXELS_PER_POINT: usize = 16;

/// The band's samples at the lattice's positions: row-major, row 0 the southernmost, NaN
/// where there is no data.
///
/// Each sample is the bilinear interpolation of the band between the centres of the four
/// pixels around the point's position in the raster: longitude and latitude transformed
/// to the raster's CRS by PROJ (one transformation over the raster's area, as GDAL's
/// warper picks it; none when the raster is in WGS84 longitude, latitude), exactly or, where
/// that is as good to 1e-4 of a pixel, interpolated between PROJ's nodes (see
/// `crate::projected`), then to
/// pixel coordinates by the inverse geotransform (rotated or sheared ones too). The pixels
/// are decoded as [`crate::read_samples`] decodes them (nodata value, mask or alpha band,
/// NaN and infinities are nodata; scale and offset applied). Pixels that are nodata or
/// outside the raster get no weight and the others' weights are renormalised; the sample
/// is NaN when no pixel of nonzero weight is valid, and when the position is outside the
/// raster's pixel edges (or PROJ cannot transform it).
///
/// Points outside the raster's pixel edges (or that PROJ cannot transform) get `outside`
/// (NaN for no data, or a height to fill the rest of the globe with, not shifted by the
/// datum); nodata within the raster stays NaN.
///
/// With a `datum` other than the ellipsoid, each valid sample `H` becomes `H + N`, the
/// geoid's height above the WGS84 ellipsoid at the point as PROJ's `vgridshift`
/// interpolates its grid ([`Geoid`]), added in `f64` before the sample is rounded to
/// `f32`.
///
/// A raster in a geographic CRS is sampled at its longitude moved by whole turns into its
/// own range (a raster in 0..360° or east of 180° is sampled at -170° too); one whose first
/// columns make exactly one turn of longitude wraps round, its pixels either side of the
/// seam interpolated together.
///
/// # Guarantees
/// Each sample depends only on the raster, the larger lattice (origin, spacing and row
/// spacing) and the point's column and row in it: any window of a lattice gets the very
/// same bits as the whole lattice at its points. Memory is bounded by blocks of the lattice, whatever its size.
///
/// # Errors
/// As [`crate::geographic_bounds`]; [`crate::Error::Read`] when GDAL fails to read the
/// band; [`crate::Error::VerticalDatum`] when the geoid's grid is missing or does not
/// cover a point with data.
pub fn sample_geographic(
    path: &Path,
    band: usize,
    lattice: &GeoLattice,
    datum: &VerticalDatum,
    outside: f32,
) -> Result<Vec<f32>> {
    let opened = OpenBand::open(path, band)?;
    let locator = Locator::new(path, &opened)?;
    let geoid = Geoid::new(datum)?;
    let (mut lons, mut lats) = (Vec::new(), Vec::new());
    let rb = opened.band()?;
    let (width, height) = (lattice.width as usize, lattice.height as usize);
    let mut out = vec![f32::NAN; width * height];
    let (mut cols, mut rows, mut values) = (Vec::new(), Vec::new(), Vec::new());
    for j0 in (0..lattice.height).step_by(BLOCK as usize) {
        for i0 in (0..lattice.width).step_by(BLOCK as usize) {
            let (j1, i1) = (
                (j0 + BLOCK).min(lattice.height),
                (i0 + BLOCK).min(lattice.width),
            );
            cols.clear();
            rows.clear();
            if locator.separable() {
                // Each column's pixel column and each row's pixel row located once.
                let xs: Vec<f64> = (i0..i1)
                    .map(|i| locator.column_of(lattice.lon(i)))
                    .collect();
                for j in j0..j1 {
                    let y = locator.row_of(lattice.lat(j));
                    for &x in &xs {
                        let inside = locator.grid.contains(x, y);
                        cols.push(if inside { x } else { f64::NAN });
                        rows.push(if inside { y } else { f64::NAN });
                    }
                }
            } else if let Some(transform) = &locator.transform {
                let pixels = |dx: f64, dy: f64| locator.pixel_length(dx, dy);
                project_block(
                    transform,
                    lattice,
                    (i0..i1, j0..j1),
                    &pixels,
                    &mut cols,
                    &mut rows,
                );
                locator.to_pixels(&mut cols, &mut rows);
            } else {
                let lons: Vec<f64> = (i0..i1).map(|i| lattice.lon(i)).collect();
                for j in j0..j1 {
                    let lat = lattice.lat(j);
                    cols.extend_from_slice(&lons);
                    rows.extend((i0..i1).map(|_| lat));
                }
                locator.to_pixels(&mut cols, &mut rows);
            }
            let footprints: Vec<Option<Footprint>> = cols
                .iter()
                .zip(&rows)
                .map(|(&c, &r)| c.is_finite().then(|| Footprint::at(c, r)))
                .collect();
            values.clear();
            values.resize(footprints.len(), f64::NAN);
            sample_points(&opened, &rb, &locator.grid, &footprints, &mut values)?;
            if let Some(geoid) = &geoid {
                add_undulations(
                    geoid,
                    lattice,
                    (i0..i1, j0..j1),
                    &mut values,
                    &mut lons,
                    &mut lats,
                )?;
            }
            if !outside.is_nan() {
                for (v, f) in values.iter_mut().zip(&footprints) {
                    if f.is_none() {
                        *v = f64::from(outside);
                    }
                }
            }
            let block_width = (i1 - i0) as usize;
            for (k, row) in values.chunks_exact(block_width).enumerate() {
                let start = (j0 as usize + k) * width + i0 as usize;
                for (slot, &v) in out[start..start + block_width].iter_mut().zip(row) {
                    *slot = v as f32;
                }
            }
        }
    }
    Ok(out)
}

/// Adds the geoid's height above the ellipsoid to each valid value of the block of the
/// lattice `columns` x `rows` (row-major in `values`); `lons`, `lats` are scratch.
fn add_undulations(
    geoid: &Geoid,
    lattice: &GeoLattice,
    (columns, rows): (std::ops::Range<u32>, std::ops::Range<u32>),
    values: &mut [f64],
    lons: &mut Vec<f64>,
    lats: &mut Vec<f64>,
) -> Result<()> {
    lons.clear();
    lats.clear();
    let points = rows.flat_map(|j| columns.clone().map(move |i| (i, j)));
    for ((i, j), v) in points.zip(values.iter()) {
        if v.is_finite() {
            lons.push(lattice.lon(i));
            lats.push(lattice.lat(j));
        }
    }
    let undulations = geoid.undulations(lons, lats)?;
    for (v, n) in values.iter_mut().filter(|v| v.is_finite()).zip(undulations) {
        *v += n;
    }
    Ok(())
}

/// Interpolates the points of `footprints` (`None`: no sample) into `values`, reading the
/// window around them, or splitting them in two when it would be much larger than they
/// need.
fn sample_points(
    opened: &OpenBand,
    rb: &RasterBand<'_>,
    grid: &PixelGrid,
    footprints: &[Option<Footprint>],
    values: &mut [f64],
) -> Result<()> {
    let mut bounds: Option<[i64; 4]> = None;
    for f in footprints.iter().flatten() {
        let b = bounds.get_or_insert([f.x0, f.y0, f.x0 + 1, f.y0 + 1]);
        *b = [
            b[0].min(f.x0),
            b[1].min(f.y0),
            b[2].max(f.x0 + 1),
            b[3].max(f.y0 + 1),
        ];
    }
    let Some([x0, y0, x1, y1]) = bounds else {
        return Ok(());
    };
    // Every point is inside the raster's pixel edges, so each has a pixel in it: the
    // clamped box is not empty.
    let (y0, y1) = (y0.max(0), y1.min(grid.height - 1));
    let (x0, x1) = match grid.turn {
        Some(_) => (x0, x1),
        None => (x0.max(0), x1.min(grid.width - 1)),
    };
    let (w, h) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
    if footprints.len() > 1 && w * h > MIN_WINDOW.max(PIXELS_PER_POINT * footprints.len()) {
        let half = footprints.len() / 2;
        let (values_a, values_b) = values.split_at_mut(half);
        sample_points(opened, rb, grid, &footprints[..half], values_a)?;
        return sample_points(opened, rb, grid, &footprints[half..], values_b);
    }
    let window = read_window(opened, rb, grid, [x0, y0], (w, h))?;
    for (f, v) in footprints.iter().zip(values.iter_mut()) {
        if let Some(f) = f {
            *v = f.interpolate_in(&window, grid);
        }
    }
    Ok(())
}

/// The `size` pixels from column `origin[0]` (before wrapping), row `origin[1]`, decoded:
/// where the columns wrap, read in pieces on either side of the seam.
fn read_window(
    opened: &OpenBand,
    rb: &RasterBand<'_>,
    grid: &PixelGrid,
    origin: [i64; 2],
    size: (usize, usize),
) -> Result<Window> {
    let (w, h) = size;
    let mut values = vec![f64::NAN; w * h];
    let y = origin[1] as usize;
    match grid.turn {
        None => opened.read_window(rb, (origin[0] as usize, y), (w, h), &mut values)?,
        Some(turn) => {
            let mut piece = Vec::new();
            let mut i = 0;
            while i < w {
                let column = (origin[0] + i as i64).rem_euclid(turn);
                let run = (w - i).min((turn - column) as usize);
                piece.resize(run * h, 0.0);
                opened.read_window(rb, (column as usize, y), (run, h), &mut piece)?;
                for (row, src) in values.chunks_exact_mut(w).zip(piece.chunks_exact(run)) {
                    row[i..i + run].copy_from_slice(src);
                }
                i += run;
            }
        }
    }
    Ok(Window {
        x0: origin[0],
        y0: origin[1],
        width: w,
        height: h,
        values,
    })
}

/// Where WGS84 positions fall in a raster, in pixel coordinates from its top-left corner.
struct Locator {
    /// PROJ's transformation from WGS84 to the raster's CRS; `None` when the raster is in
    /// WGS84 longitude, latitude.
    transform: Option<CoordTransform>,
    /// For a geographic CRS: the west edge of the raster's corner box and a turn of
    /// longitude, in the CRS's unit; x is moved by whole turns to at or east of that edge.
    wrap: Option<(f64, f64)>,
    geo_transform: [f64; 6],
    grid: PixelGrid,
}

impl Locator {
    fn new(path: &Path, opened: &OpenBand) -> Result<Locator> {
        let info = &opened.info;
        let gt = geo_transform(path, info)?;
        let source = source_crs(path, opened)?;
        let wgs84_lon_lat = info.crs_wkt.as_deref().is_some_and(crate::is_wgs84_lon_lat);
        let transform = if wgs84_lon_lat {
            None
        } else {
            // As GDAL's warper does: over the raster's area PROJ picks one transformation
            // (among several of a datum's, each with its own area of use) for every point.
            let mut options = CoordTransformOptions::new().map_err(|e| warp_error(path, e))?;
            if let Some([w, s, e, n]) = area_of_interest(path, opened) {
                options
                    .set_area_of_interest(w, s, e, n)
                    .map_err(|err| warp_error(path, err))?;
            }
            Some(
                CoordTransform::new_with_options(&wgs84()?, &source, &options)
                    .map_err(|e| warp_error(path, e))?,
            )
        };
        let turn = if !source.is_geographic() {
            None
        } else if wgs84_lon_lat || (source.angular_units() - 1f64.to_radians()).abs() < 1e-12 {
            Some(360.0)
        } else {
            Some(std::f64::consts::TAU / source.angular_units())
        };
        let wrap = turn.map(|turn| (corner_box(&gt, info)[0], turn));
        let grid = PixelGrid {
            width: i64::from(info.width),
            height: i64::from(info.height),
            turn: turn.and_then(|turn| columns_in_a_turn(&gt, info.width, turn)),
        };
        Ok(Locator {
            transform,
            wrap,
            geo_transform: gt,
            grid,
        })
    }

    /// Replaces each position in `xs`, `ys` (the raster's CRS; infinite or NaN where
    /// PROJ could not transform it) by its column and row in the raster (pixel edges at
    /// whole numbers), or by NaN when it is not finite or lies outside the raster's pixel
    /// edges. Each point's result depends on that point alone.
    fn to_pixels(&self, xs: &mut [f64], ys: &mut [f64]) {
        let gt = &self.geo_transform;
        let rotated = self.rotated();
        let det = gt[1] * gt[5] - gt[2] * gt[4];
        for (x, y) in xs.iter_mut().zip(ys.iter_mut()) {
            let mut position = None;
            if x.is_finite() && y.is_finite() {
                let (col, row) = if rotated {
                    let (dx, dy) = (self.wrapped(*x) - gt[0], *y - gt[3]);
                    (
                        (gt[5] * dx - gt[2] * dy) / det,
                        (gt[1] * dy - gt[4] * dx) / det,
                    )
                } else {
                    (self.column_of(*x), self.row_of(*y))
                };
                position = Some((col, row)).filter(|&(c, r)| self.grid.contains(c, r));
            }
            (*x, *y) = position.unwrap_or((f64::NAN, f64::NAN));
        }
    }
}

impl Locator {
    /// The length in pixels of displacement `dx`, `dy` in the raster's CRS: the larger of
    /// its column and row parts.
    fn pixel_length(&self, dx: f64, dy: f64) -> f64 {
        let gt = &self.geo_transform;
        let det = gt[1] * gt[5] - gt[2] * gt[4];
        let column = (gt[5] * dx - gt[2] * dy) / det;
        let row = (gt[1] * dy - gt[4] * dx) / det;
        column.abs().max(row.abs())
    }

    /// Whether the geotransform is rotated or sheared.
    fn rotated(&self) -> bool {
        let gt = &self.geo_transform;
        gt[2] != 0.0 || gt[4] != 0.0
    }

    /// Whether a point's column depends on its longitude alone and its row on its latitude
    /// alone (no PROJ transformation, a north-up raster): [`Locator::locate`] is then
    /// [`Locator::column_of`] and [`Locator::row_of`], kept where `grid.contains` them.
    fn separable(&self) -> bool {
        self.transform.is_none() && !self.rotated()
    }

    /// `x` moved by whole turns to at or east of the raster's west edge (geographic CRS).
    fn wrapped(&self, x: f64) -> f64 {
        match self.wrap {
            Some((west, turn)) => west + (x - west).rem_euclid(turn),
            None => x,
        }
    }

    /// The pixel column of `x` (the raster's CRS) on a north-up raster.
    fn column_of(&self, x: f64) -> f64 {
        (self.wrapped(x) - self.geo_transform[0]) / self.geo_transform[1]
    }

    /// The pixel row of `y` (the raster's CRS) on a north-up raster.
    fn row_of(&self, y: f64) -> f64 {
        (y - self.geo_transform[3]) / self.geo_transform[5]
    }
}

/// The columns of one turn of longitude (`turn` in the CRS's unit) of a north-up raster
/// whose first columns make exactly one turn (to a millionth of a pixel; a repeated last
/// column is left out), or `None`.
fn columns_in_a_turn(gt: &[f64; 6], width: u32, turn: f64) -> Option<i64> {
    if gt[2] != 0.0 || gt[4] != 0.0 || gt[1].is_nan() || gt[1] <= 0.0 {
        return None;
    }
    let columns = turn / gt[1];
    let whole = columns.round();
    ((columns - whole).abs() <= 1e-6 && whole >= 2.0 && whole <= f64::from(width))
        .then_some(whole as i64)
}
