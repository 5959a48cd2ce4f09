//! `layer.json` and the tiles' availability metadata (which tiles exist below each one).

use std::collections::BTreeSet;

use tinsmith_raster::GeoBounds;

use crate::tms::bounds_array;
use crate::TerrainOptions;

/// Levels whose tiles carry the metadata extension: 0, N, 2N, ... (`metadataAvailability`).
pub const METADATA_AVAILABILITY: u8 = 10;

/// Which tiles exist, per level.
pub(super) type Available = Vec<BTreeSet<(u32, u32)>>;

/// `available` tiles of one level as `{startX, startY, endX, endY}` rectangles (runs of
/// columns along each row, merged with identical runs of the rows above), restricted to
/// columns `x_range` and rows `y_range`.
pub(super) fn rectangles(
    tiles: &BTreeSet<(u32, u32)>,
    x_range: [u32; 2],
    y_range: [u32; 2],
) -> Vec<[u32; 4]> {
    let mut by_row: std::collections::BTreeMap<u32, Vec<[u32; 2]>> = Default::default();
    for &(x, y) in tiles {
        if x < x_range[0] || x > x_range[1] || y < y_range[0] || y > y_range[1] {
            continue;
        }
        let runs = by_row.entry(y).or_default();
        match runs.last_mut() {
            Some(run) if run[1] + 1 == x => run[1] = x,
            _ => runs.push([x, x]),
        }
    }
    // The set is ordered by x first, so each row's columns arrive in increasing order.
    let mut out: Vec<[u32; 4]> = Vec::new();
    let mut open: Vec<[u32; 4]> = Vec::new();
    for (&y, runs) in &by_row {
        let mut next_open = Vec::new();
        for run in runs {
            match open
                .iter()
                .position(|r| r[0] == run[0] && r[2] == run[1] && r[3] + 1 == y)
            {
                Some(k) => {
                    let mut r = open.swap_remove(k);
                    r[3] = y;
                    next_open.push(r);
                }
                None => next_open.push([run[0], y, run[1], y]),
            }
        }
        out.append(&mut open);
        open = next_open;
    }
    out.append(&mut open);
    out.sort_by_key(|r| (r[1], r[0]));
    out
}

/// A rectangle of available tiles, `{startX, startY, endX, endY}`, as `layer.json` and the
/// metadata extension both write it.
#[derive(serde::Serialize)]
struct TileRange {
    #[serde(rename = "startX")]
    start_x: u32,
    #[serde(rename = "startY")]
    start_y: u32,
    #[serde(rename = "endX")]
    end_x: u32,
    #[serde(rename = "endY")]
    end_y: u32,
}

/// `available` tiles of one level, in the given columns and rows, as [`TileRange`]s.
fn tile_ranges(
    tiles: &BTreeSet<(u32, u32)>,
    x_range: [u32; 2],
    y_range: [u32; 2],
) -> Vec<TileRange> {
    rectangles(tiles, x_range, y_range)
        .into_iter()
        .map(|[start_x, start_y, end_x, end_y]| TileRange {
            start_x,
            start_y,
            end_x,
            end_y,
        })
        .collect()
}

/// The metadata extension of tile z/x/y: availability of levels z+1 ..= z+10 below it.
pub(super) fn metadata_json(available: &Available, z: u8, x: u32, y: u32) -> String {
    #[derive(serde::Serialize)]
    struct Metadata {
        available: Vec<Vec<TileRange>>,
    }
    let mut levels = Vec::new();
    for k in 1..=u32::from(METADATA_AVAILABILITY) {
        let level = usize::from(z) + k as usize;
        let Some(tiles) = available.get(level) else {
            break;
        };
        let f = 1u32 << k;
        levels.push(tile_ranges(
            tiles,
            [x * f, (x + 1) * f - 1],
            [y * f, (y + 1) * f - 1],
        ));
    }
    // Trailing empty levels say nothing; CesiumJS needs no entry for them.
    while levels.last().is_some_and(Vec::is_empty) {
        levels.pop();
    }
    let metadata = Metadata { available: levels };
    serde_json::to_string(&metadata).expect("tile ranges serialize")
}

/// The text of `layer.json` for a pyramid named `name`.
pub(super) fn layer_json(
    name: &str,
    options: &TerrainOptions,
    bounds: &GeoBounds,
    max_zoom: u8,
    available: &Available,
) -> String {
    let mut extensions = Vec::new();
    if options.normals {
        extensions.push(serde_json::json!("octvertexnormals"));
    }
    if options.water.is_some() {
        extensions.push(serde_json::json!("watermask"));
    }
    if options.metadata {
        extensions.push(serde_json::json!("metadata"));
    }
    let all = [0, u32::MAX];
    // The deepest level that has tiles (a tiny raster's finest levels may have none).
    let max_zoom = available
        .iter()
        .rposition(|tiles| !tiles.is_empty())
        .map_or(max_zoom, |z| z as u8);
    let available: Vec<Vec<TileRange>> = available[..=usize::from(max_zoom)]
        .iter()
        .map(|tiles| tile_ranges(tiles, all, all))
        .collect();
    let mut layer = serde_json::json!({
        "tilejson": "2.1.0",
        "name": name,
        "description": "made by tinsmith",
        "version": "1.0.0",
        "format": "quantized-mesh-1.0",
        "scheme": "tms",
        "projection": options.tiling.projection(),
        "tiles": ["{z}/{x}/{y}.terrain?v={version}"],
        "minzoom": options.min_zoom,
        "maxzoom": max_zoom,
        "bounds": bounds_array(bounds),
        "extensions": extensions,
        "available": available,
        "attribution": "",
    });
    if options.metadata {
        layer["metadataAvailability"] = serde_json::json!(METADATA_AVAILABILITY);
    }
    serde_json::to_string_pretty(&layer).expect("JSON values serialize")
}
