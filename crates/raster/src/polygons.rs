//! Polygon layers burnt onto a longitude/latitude grid: where water is, from a layer of
//! coastlines, seas and lakes that GDAL reads (GeoPackage, Shapefile, GeoJSON,
//! FlatGeobuf...).

use std::path::Path;

use gdal::raster::{rasterize, RasterizeOptions};
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use gdal::vector::{Geometry, LayerAccess};
use gdal::{Dataset, DatasetOptions, DriverManager, GdalOpenFlags};

use crate::error::{Error, Result};

/// Whether GDAL opens `path` as a vector dataset with at least one layer.
pub fn is_vector(path: &Path) -> bool {
    open_vector(path).is_ok_and(|ds| ds.layer_count() > 0)
}

pub(crate) fn open_vector(path: &Path) -> std::result::Result<Dataset, gdal::errors::GdalError> {
    Dataset::open_ex(
        path,
        DatasetOptions {
            open_flags: GdalOpenFlags::GDAL_OF_VECTOR | GdalOpenFlags::GDAL_OF_READONLY,
            ..Default::default()
        },
    )
}

/// The `cells` x `cells` grid over the longitude, latitude rectangle `[west, south, east,
/// north]` (row 0 the northernmost), 255 where a cell's centre lies inside a polygon of any
/// layer of the vector dataset at `path`, 0 elsewhere. Polygons in another CRS are
/// transformed to WGS84 longitude, latitude by PROJ; lines and points burn nothing. Each
/// cell depends only on the polygons and its centre.
///
/// # Errors
/// [`Error::Polygons`] naming `path` when GDAL cannot open or read it, or PROJ cannot
/// transform a polygon.
pub fn burn_polygons(path: &Path, rect: [f64; 4], cells: u32) -> Result<Vec<u8>> {
    let failed = |e: gdal::errors::GdalError| Error::Polygons {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let dataset = open_vector(path).map_err(failed)?;
    let [west, south, east, north] = rect;
    let mut lon_lat = SpatialRef::from_epsg(4326).map_err(failed)?;
    lon_lat.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut polygons: Vec<Geometry> = Vec::new();
    for mut layer in dataset.layers() {
        let to_lon_lat = match layer.spatial_ref() {
            Some(mut srs) => {
                srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
                // Only the features near the rectangle, by its box in the layer's CRS.
                let back = CoordTransform::new(&lon_lat, &srs).map_err(failed)?;
                let mut xs: Vec<f64> = (0..=8).flat_map(|_| [west, east]).collect();
                let mut ys: Vec<f64> = (0..=8)
                    .flat_map(|k| {
                        let lat = south + (north - south) * f64::from(k) / 8.0;
                        [lat, lat]
                    })
                    .collect();
                xs.extend((0..=8).flat_map(|k| {
                    let lon = west + (east - west) * f64::from(k) / 8.0;
                    [lon, lon]
                }));
                ys.extend((0..=8).flat_map(|_| [south, north]));
                if back.transform_coords(&mut xs, &mut ys, &mut []).is_ok()
                    && xs.iter().chain(&ys).all(|v| v.is_finite())
                {
                    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
                    let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    layer.set_spatial_filter_rect(min(&xs), min(&ys), max(&xs), max(&ys));
                }
                Some(CoordTransform::new(&srs, &lon_lat).map_err(failed)?)
            }
            None => {
                layer.set_spatial_filter_rect(west, south, east, north);
                None
            }
        };
        for feature in layer.features() {
            let Some(geometry) = feature.geometry() else {
                continue;
            };
            let mut geometry = geometry.clone();
            if let Some(transform) = &to_lon_lat {
                geometry.transform_inplace(transform).map_err(failed)?;
            }
            polygons.push(geometry);
        }
    }
    let driver = DriverManager::get_driver_by_name("MEM").map_err(failed)?;
    let side = cells as usize;
    let mut grid = driver
        .create_with_band_type::<u8, _>("", side, side, 1)
        .map_err(failed)?;
    let size = [
        (east - west) / f64::from(cells),
        (north - south) / f64::from(cells),
    ];
    grid.set_geo_transform(&[west, size[0], 0.0, north, 0.0, -size[1]])
        .map_err(failed)?;
    if !polygons.is_empty() {
        let burn = vec![255.0; polygons.len()];
        let options = RasterizeOptions {
            all_touched: false,
            ..Default::default()
        };
        rasterize(&mut grid, &[1], &polygons, &burn, Some(options)).map_err(failed)?;
    }
    let band = grid.rasterband(1).map_err(failed)?;
    let buffer = band
        .read_as::<u8>((0, 0), (side, side), (side, side), None)
        .map_err(failed)?;
    Ok(buffer.data().to_vec())
}

/// Opens the vector file at `path` for a reader that reports its problems as
/// [`Error::Lines`]: [`Error::NotFound`] when nothing is there, else GDAL's refusal.
pub(crate) fn open_vector_file(path: &Path) -> Result<Dataset> {
    if !path.exists() {
        return Err(Error::NotFound {
            path: path.to_path_buf(),
        });
    }
    open_vector(path).map_err(|e| Error::Lines {
        path: path.to_path_buf(),
        reason: format!("not a vector file GDAL can read ({e})"),
    })
}

/// The CRS (WKT) every layer of one file must share: the first layer's, as each layer
/// comes (`seen` starts as `None`); refuses, naming the layer, one that declares another.
pub(crate) fn same_layer_crs(
    seen: &mut Option<Option<String>>,
    layer: &gdal::vector::Layer<'_>,
    path: &Path,
) -> Result<()> {
    let wkt = layer.spatial_ref().and_then(|s| s.to_wkt().ok());
    match seen {
        None => *seen = Some(wkt),
        Some(first) if *first != wkt => {
            return Err(Error::Lines {
                path: path.to_path_buf(),
                reason: format!(
                    "layer {} has another CRS than the first layer",
                    layer.name()
                ),
            })
        }
        Some(_) => {}
    }
    Ok(())
}
