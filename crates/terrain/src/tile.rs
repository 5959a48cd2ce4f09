//! One tile: decimated with its edges locked, verified, and encoded as quantized-mesh or
//! as a 3D Tiles GLB.

use crate::glb_tile::{GlbTile, TileBounds};
use crate::quantized_mesh::{gzip, QuantizedMeshTile, QUANTIZED_MAX};
use tinsmith_core::{decimate_with_border, DecimationOptions, Grid, VertexHeights};
use tinsmith_tiling::check_tin;

use crate::budget::{quanta_per_step, slack_scale, LevelBudget};
use crate::globe_edges::globe_edges;
use crate::layer::{metadata_json, Available};
use crate::order::encoding_order;
use crate::rows::LevelRows;
use crate::tms::Tiling;
use crate::{TerrainError, TerrainOptions, TerrainResult, TileFormat};
use tinsmith_tiling::{edge_limit, EdgeProfile};

/// One tile done on a worker.
pub(super) struct TileOut {
    pub(super) x: u32,
    pub(super) y: u32,
    pub(super) bytes: Vec<u8>,
    pub(super) vertices: usize,
    pub(super) triangles: usize,
    pub(super) max_error: f64,
    /// The bound the tile was verified against (see [`LevelBudget::verify`]).
    pub(super) verified_bound: f64,
    /// A 3D Tiles tile's metadata (for its subtree).
    pub(super) bounds: Option<TileBounds>,
}

pub(super) fn build_tile(
    raster: &LevelRows,
    x: u32,
    y: u32,
    budget: &LevelBudget,
    options: &TerrainOptions,
    metadata_available: Option<&Available>,
) -> TerrainResult<Option<TileOut>> {
    let z = raster.level;
    // Where the tile is written (`x` may be a turn east, see `tile_range`).
    let column = raster.tiling.tile_column(z, x);
    let cells = raster.tiling.cells;
    let n = cells as usize;
    let (i0, j0) = raster.tile_origin(x, y);
    let values = raster.tile_values(x, y);
    let scale = slack_scale(values.iter().copied());
    let largest = values
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if largest >= f64::from(f32::MAX) / 2.0 {
        return Err(TerrainError::HeightsBeyondF32 {
            z,
            x: column,
            y,
            max_abs: largest,
        });
    }
    let grid = Grid::new(cells + 1, cells + 1, values).expect("a tile's lattice");
    if grid.valid_cell_count() == 0 {
        return Ok(None);
    }
    // Vertices are samples, and every sample of a valid cell is within the decimation's
    // bound of the mesh (at most the level's bound plus a step where heights lie close
    // enough to 0 for the check below to pass): the mesh's heights span at least those
    // samples' less twice that. Past the level's capacity by more than a step, the check
    // after decimation would refuse the tile; that is said now (the border's 1-D rule
    // could fail first on such a span). Samples of no valid cell are never measured.
    let (low, high) = valid_cell_range(&grid);
    if high - low - 2.0 * budget.bound > budget.capacity() + 3.0 * budget.step {
        return Err(TerrainError::TileHeights {
            z,
            x: column,
            y,
            low,
            high,
            capacity: budget.capacity(),
        });
    }

    // Edges are measured on the globe: capped at coarse levels, and at every level no
    // triangle may turn over as drawn there.
    let globe = globe_edges(raster.tiling, z, column, y, budget.max_edge);
    // Shared edges, each decided from the level raster alone (its samples and their
    // magnitude) and the edge's place on the globe: both neighbours agree.
    let keep = |edge: EdgeProfile, side: usize| {
        let scale = slack_scale(edge.values().iter().copied());
        let limit = edge_limit(budget.decimation(scale), scale);
        let span = globe.spans[side];
        if limit > 0.0 {
            edge.simplify(limit, span)
        } else {
            vec![true; n + 1]
        }
    };
    let south = keep(raster.edge(i0, j0, true), 0);
    let north = keep(raster.edge(i0, j0 + n, true), 1);
    let west = keep(raster.edge(i0, j0, false), 2);
    let east = keep(raster.edge(i0 + n, j0, false), 3);
    let last = cells;
    let keep_border = |gx: u32, gy: u32| {
        if gy == 0 {
            south[gx as usize]
        } else if gy == last {
            north[gx as usize]
        } else if gx == 0 {
            west[gy as usize]
        } else if gx == last {
            east[gy as usize]
        } else {
            true
        }
    };
    // Vertices at their samples: flat ground (the sea at 0, a tile the raster does not
    // reach) stays exactly at its height in the quantized tiles.
    let mut decimation_options = DecimationOptions::new(budget.decimation(scale))
        .with_vertex_heights(VertexHeights::Samples);
    decimation_options.max_abs_value = Some(scale);
    decimation_options.max_edge_length = budget.max_edge;
    decimation_options.edge_metric = globe.metric;
    let tin = decimate_with_border(&grid, &decimation_options, &keep_border, &mut |_| {})
        .map_err(|source| TerrainError::Decimate {
            z,
            x: column,
            y,
            source,
        })?
        .tin;
    if tin.triangles().is_empty() {
        return Ok(None);
    }

    // Heights on the level's lattice: tile minimum rounded down to a multiple of the step.
    let s = budget.step;
    let (lo, hi) = tin
        .vertices()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.z), hi.max(v.z))
        });
    let k_min = (lo / s).floor();
    let top = (hi / s).round() - k_min;
    if top > f64::from(QUANTIZED_MAX - 1) || k_min.abs() + f64::from(QUANTIZED_MAX) >= 16_777_216.0
    {
        return Err(TerrainError::TileHeights {
            z,
            x: column,
            y,
            low: lo,
            high: hi,
            capacity: budget.capacity(),
        });
    }
    let min_height = k_min * s;
    let per_step = quanta_per_step(k_min, top);
    let max_height = min_height + f64::from(QUANTIZED_MAX) * s / f64::from(per_step);
    let quantized: Vec<[u16; 3]> = tin
        .vertices()
        .iter()
        .map(|v| {
            let h = ((v.z / s).round() - k_min) * f64::from(per_step);
            [
                (v.x * raster.tiling.u_per_cell()) as u16,
                (v.y * raster.tiling.u_per_cell()) as u16,
                h.clamp(0.0, f64::from(QUANTIZED_MAX)) as u16,
            ]
        })
        .collect();

    // The promise, checked on what the decoder will compute.
    let decoded = |i: usize, _: &_| min_height + f64::from(quantized[i][2] / per_step as u16) * s;
    let check = check_tin(&grid, &tin, decoded, budget.verify(scale)).map_err(|e| {
        TerrainError::Verify {
            z,
            x: column,
            y,
            problems: e.to_string(),
        }
    })?;
    if !check.passed() {
        return Err(TerrainError::Verify {
            z,
            x: column,
            y,
            problems: check.problems.join("; "),
        });
    }

    // At its own column's longitudes, as a window that does not wrap places it.
    let rect = raster.tiling.tile_rectangle(z, column, y);
    let normals: Option<Vec<[f64; 3]>> = options.normals.then(|| {
        let d = raster.tiling.step(z);
        // Rows are evenly spaced in latitude inside the tile, as CesiumJS places `v`.
        let d_lat = match raster.tiling.tiling {
            Tiling::Geographic => d,
            Tiling::Mercator => (rect.north - rect.south) / f64::from(cells),
        };
        // A vertex's longitude from its lattice column round the globe, so that the
        // tiles either side of 180 degrees see one longitude (180 and -180 gave normals
        // whose east component, near 0, rounded to either side of the oct encoding's 0).
        let turn = raster.tiling.columns(z) * u64::from(cells);
        tin.vertices()
            .iter()
            .map(|v| {
                let (gi, gj) = (i0 + v.x as usize, j0 + v.y as usize);
                let lattice_column = (u64::from(column) * u64::from(cells) + v.x as u64) % turn;
                raster.normal(
                    gi,
                    gj,
                    -180.0 + lattice_column as f64 * d,
                    rect.south + f64::from(v.y) * d_lat,
                )
            })
            .collect()
    });
    let triangles = encoding_order(&quantized, tin.triangles());
    let encode_error = |source| TerrainError::Encode {
        z,
        x: column,
        y,
        source,
    };
    let water = match &options.water {
        Some(water) => Some(crate::water::mask(water, rect)?),
        None => None,
    };
    let (bytes, bounds) = match options.format {
        TileFormat::ThreeDTiles => {
            // The decoded heights the check above measured, on the level's lattice.
            let heights: Vec<f64> = quantized
                .iter()
                .map(|q| min_height + f64::from(q[2] / per_step as u16) * s)
                .collect();
            let mut tile = GlbTile::new(rect, &quantized, &heights, &triangles);
            if let Some(normals) = &normals {
                tile = tile.with_normals(normals);
            }
            if let Some(water) = &water {
                tile = tile.with_water_mask(water.bytes());
            }
            let (bytes, bounds) = tile.encode().map_err(encode_error)?;
            (bytes, Some(bounds))
        }
        TileFormat::QuantizedMesh => {
            let metadata =
                metadata_available.map(|available| metadata_json(available, z, column, y));
            let mut tile = QuantizedMeshTile::new(
                rect,
                min_height as f32,
                max_height as f32,
                &quantized,
                &triangles,
            );
            if let Some(normals) = &normals {
                tile = tile.with_normals(normals);
            }
            if let Some(water) = &water {
                tile = tile.with_water_mask(water.bytes());
            }
            if let Some(metadata) = &metadata {
                tile = tile.with_metadata(metadata);
            }
            let mut bytes = tile.encode().map_err(encode_error)?;
            if options.gzip {
                bytes = gzip(&bytes);
            }
            (bytes, None)
        }
    };
    Ok(Some(TileOut {
        x: column,
        y,
        bytes,
        vertices: quantized.len(),
        triangles: tin.triangles().len(),
        max_error: check.max_error,
        verified_bound: budget.verify(scale),
        bounds,
    }))
}

/// The lowest and highest samples of `grid` that are corners of a valid cell (infinite
/// the wrong way round when there is none).
fn valid_cell_range(grid: &Grid) -> (f64, f64) {
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let values = grid.values();
    let mut range = (f64::INFINITY, f64::NEG_INFINITY);
    for y in 0..h.saturating_sub(1) {
        for x in 0..w - 1 {
            let corners =
                [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)].map(|(i, j)| values[j * w + i]);
            if corners.iter().all(|v| v.is_finite()) {
                for v in corners {
                    range = (range.0.min(v), range.1.max(v));
                }
            }
        }
    }
    range
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_of_no_valid_cell_does_not_count_towards_the_heights_range() {
        // A 4 x 4 lattice: a valid block of 2 x 2 cells at 10 to 13, and an isolated
        // sample of 5000 whose cells all have a nodata corner (never a vertex).
        let n = f64::NAN;
        #[rustfmt::skip]
        let values = vec![
            10.0, 11.0, 12.0, n,
            11.0, 12.0, 13.0, n,
            12.0, 13.0, 12.0, n,
            n,    n,    n,    5000.0,
        ];
        let grid = Grid::new(4, 4, values).unwrap();
        assert_eq!(valid_cell_range(&grid), (10.0, 13.0));
    }
}
