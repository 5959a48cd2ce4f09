//! A base raster under the input ([`BaseRaster`], `tiles HIGH --base LOW`): the pyramid's
//! extent grows to both, and every lattice sample is the input's where the input has a
//! valid one, the base's elsewhere ([`Stacked`]), so that each level is still one lattice
//! sampled point by point and same-level neighbours share their edges wherever the
//! inputs meet.

use std::ops::Range;
use std::path::{Path, PathBuf};

use tinsmith_raster::{GeoBounds, VerticalDatum};

use crate::rows::LevelRows;
use crate::stream::{RowSource, Warp};
use crate::{TerrainError, TerrainOptions, TerrainResult};

/// A raster whose heights fill the pyramid wherever the input has none: beyond its
/// extent and at its nodata. Band 1 is read, its heights above `vertical_datum`.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseRaster {
    /// Any georeferenced raster GDAL reads (several: a VRT of them).
    pub path: PathBuf,
    /// What its heights are above (its own, chosen as the input's is).
    pub vertical_datum: VerticalDatum,
}

/// The input's samples where they are valid, then each next layer's where all before
/// had none. Each sample depends only on the layers and its position, as each layer's
/// does ([`Warp`]).
pub(super) struct Stacked<'a> {
    /// By priority, the input first.
    layers: Vec<Warp<'a>>,
    /// With a base: the input's extent widened by a margin (west, south, east, north),
    /// beyond which it has no sample, so that it is not sampled there: a global base's
    /// coarse levels would otherwise transform every point of the globe into the input's
    /// CRS.
    reach: Option<[f64; 4]>,
}

impl<'a> Stacked<'a> {
    /// `input` over `options.base` (when given); points beyond every layer get
    /// [`TerrainOptions::outside`].
    ///
    /// # Errors
    /// As [`tinsmith_raster::geographic_bounds`] of `input`.
    pub(super) fn new(input: &'a Path, options: &'a TerrainOptions) -> TerrainResult<Stacked<'a>> {
        let outside = options.outside();
        let mut layers = vec![Warp {
            path: input,
            band: options.band,
            datum: &options.vertical_datum,
            outside,
        }];
        let mut reach = None;
        if let Some(base) = &options.base {
            layers[0].outside = f32::NAN;
            layers.push(Warp {
                path: &base.path,
                band: 1,
                datum: &base.vertical_datum,
                outside,
            });
            // The extent's edges are densified, so a point within the input's pixel edges
            // is within a small fraction of it: a hundredth of its span and ten samples
            // is far more than curved edges between densified points depart from it.
            let b = tinsmith_raster::geographic_bounds(input, options.band)?;
            let margin = |span: f64| span / 100.0 + 10.0 * b.resolution;
            let (dx, dy) = (margin(b.east - b.west), margin(b.north - b.south));
            reach = Some([b.west - dx, b.south - dy, b.east + dx, b.north + dy]);
        }
        Ok(Stacked { layers, reach })
    }

    /// The input's samples at rows `rows`, columns `columns` of `level`: only within its
    /// reach, NaN beyond.
    fn input_rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>> {
        let Some([west, south, east, north]) = self.reach else {
            return self.layers[0].rows(level, rows, columns);
        };
        let lattice = level.lattice(rows.clone(), columns.clone());
        let (width, height) = (columns.len(), rows.len());
        let span = east - west;
        let within = |lon: f64| span >= 360.0 || (lon - west).rem_euclid(360.0) <= span;
        let first_last = |hits: &mut dyn Iterator<Item = usize>| {
            let first = hits.next()?;
            Some(first..hits.last().unwrap_or(first) + 1)
        };
        let in_columns = first_last(&mut (0..width).filter(|&i| within(lattice.lon(i as u32))));
        let in_rows = first_last(&mut (0..height).filter(|&j| {
            let lat = lattice.lat(j as u32);
            (south..=north).contains(&lat)
        }));
        let mut out = vec![f32::NAN; width * height];
        let (Some(i), Some(j)) = (in_columns, in_rows) else {
            return Ok(out);
        };
        let values = self.layers[0].rows(
            level,
            rows.start + j.start..rows.start + j.end,
            columns.start + i.start..columns.start + i.end,
        )?;
        for (k, row) in values.chunks_exact(i.len()).enumerate() {
            let start = (j.start + k) * width + i.start;
            out[start..start + i.len()].copy_from_slice(row);
        }
        Ok(out)
    }
}

impl RowSource for Stacked<'_> {
    fn rows(
        &self,
        level: &LevelRows,
        rows: Range<usize>,
        columns: Range<usize>,
    ) -> TerrainResult<Vec<f32>> {
        let width = columns.len();
        let mut out = self.input_rows(level, rows.clone(), columns.clone())?;
        for layer in &self.layers[1..] {
            // Only the smallest window holding every sample still missing is sampled.
            let missing = out.iter().enumerate().filter(|(_, v)| v.is_nan());
            let Some((i0, i1, j0, j1)) = missing.fold(None, |b, (k, _)| {
                let (i, j) = (k % width, k / width);
                let (i0, i1, j0, j1) = b.unwrap_or((i, i, j, j));
                Some((i0.min(i), i1.max(i), j0.min(j), j1.max(j)))
            }) else {
                break;
            };
            let below = layer.rows(
                level,
                rows.start + j0..rows.start + j1 + 1,
                columns.start + i0..columns.start + i1 + 1,
            )?;
            let window = i1 - i0 + 1;
            for (k, v) in below.into_iter().enumerate() {
                let slot = &mut out[(j0 + k / window) * width + i0 + k % window];
                if slot.is_nan() {
                    *slot = v;
                }
            }
        }
        Ok(out)
    }
}

/// The smallest extent holding both `a` and `b` (round the globe the shorter way when they
/// are apart), at `a`'s resolution.
pub(super) fn union(a: &GeoBounds, b: &GeoBounds) -> GeoBounds {
    let south = a.south.min(b.south);
    let north = a.north.max(b.north);
    // `b` moved by whole turns to the place where the two together span least.
    let span = |k: f64| (a.east.max(b.east + k) - a.west.min(b.west + k), k);
    let (width, k) = [-360.0, 0.0, 360.0]
        .map(span)
        .into_iter()
        .fold((f64::INFINITY, 0.0), |m, s| if s.0 < m.0 { s } else { m });
    let (west, east) = if width >= 360.0 {
        (-180.0, 180.0)
    } else {
        // West in -180..180, as `geographic_bounds` gives it (east then past 180).
        let west = a.west.min(b.west + k);
        let turns = ((west + 180.0) / 360.0).floor() * 360.0;
        (west - turns, a.east.max(b.east + k) - turns)
    };
    GeoBounds {
        west,
        south,
        east,
        north,
        resolution: a.resolution,
    }
}

/// Refuses the options a base raster does not work with, naming them and why.
pub(super) fn refuse_clashes(options: &TerrainOptions) -> TerrainResult<()> {
    if options.base.is_none() {
        return Ok(());
    }
    if let Some(crate::Water::SeaLevel { .. }) = options.water {
        return Err(TerrainError::Options(
            "--water sea-level cannot be combined with --base: it reads the sea from the \
             input's nodata, which the base fills; give a water raster or polygon layer"
                .into(),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds(west: f64, east: f64) -> GeoBounds {
        GeoBounds {
            west,
            south: 0.0,
            east,
            north: 1.0,
            resolution: 0.1,
        }
    }

    #[test]
    fn the_union_goes_the_short_way_round() {
        let u = union(&bounds(10.0, 20.0), &bounds(-5.0, 12.0));
        assert_eq!((u.west, u.east), (-5.0, 20.0));
        // Across the antimeridian: 170..190 and -175..-160 meet east of 180.
        let u = union(&bounds(170.0, 190.0), &bounds(-175.0, -160.0));
        assert_eq!((u.west, u.east), (170.0, 200.0));
        let u = union(&bounds(-175.0, -160.0), &bounds(170.0, 190.0));
        assert_eq!((u.west, u.east), (170.0, 200.0));
        let u = union(&bounds(-180.0, 180.0), &bounds(10.0, 20.0));
        assert_eq!((u.west, u.east), (-180.0, 180.0));
        let u = union(&bounds(10.0, 20.0), &bounds(-180.0, 180.0));
        assert_eq!((u.west, u.east), (-180.0, 180.0));
    }
}
