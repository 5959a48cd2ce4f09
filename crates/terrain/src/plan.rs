//! What every shard of a pyramid agrees on before any work: the input's fingerprint, the
//! options, where the pyramid is cut into blocks, and which blocks each shard builds
//! (balanced by the valid samples they hold, not by their count).

use std::ops::Range;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use tinsmith_raster::GeoBounds;

use crate::blocks::{blocks, domain, lowest_split, split_fits, Cut};
use crate::records::hex;
use crate::tms::{Scheme, TileRect, Tiling, LATTICE_CELLS};
use crate::{TerrainOptions, TerrainResult};

/// Cells a side of the coarse read that fingerprints the input and weighs the blocks.
const COVERAGE_SIDE: usize = 512;

/// Blocks wanted per shard, so that whole blocks can balance the shards' work.
const BLOCKS_PER_SHARD: u64 = 8;

/// Shard `index` of `count` (0-based: `--shard 0/7` to `--shard 6/7`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, from 0.
    pub index: u32,
    /// How many shards the run has.
    pub count: u32,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// Parses `I/N` with `0 <= I < N`.
    fn from_str(text: &str) -> Result<Shard, String> {
        let bad = || format!("{text:?} is not a shard: give I/N, with I from 0 to N-1 (e.g. 0/8)");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count): (u32, u32) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The options that shape the tiles' bytes, as a plan records them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct TileOptions {
    pub(super) band: usize,
    pub(super) min_zoom: u8,
    pub(super) max_zoom: u8,
    pub(super) quality: f64,
    pub(super) normals: bool,
    pub(super) metadata: bool,
    pub(super) gzip: bool,
    /// The vertical datum as [`tinsmith_raster::VerticalDatum::parse`] reads it; absent
    /// for the ellipsoid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) vertical_datum: Option<String>,
    /// Where the water mask comes from; absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) water: Option<crate::Water>,
    /// [`TerrainOptions::whole_globe`]; absent when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub(super) whole_globe: bool,
    /// [`TerrainOptions::tiling`]; absent when geographic.
    #[serde(default, skip_serializing_if = "is_geographic")]
    pub(super) tiling: Tiling,
    /// Cells a side of the tiles' lattices ([`crate::tms::lattice_cells`]); absent for the
    /// default.
    #[serde(default = "default_cells", skip_serializing_if = "is_default_cells")]
    pub(super) cells: u32,
    /// [`TerrainOptions::format`]; absent for quantized-mesh.
    #[serde(default, skip_serializing_if = "is_quantized_mesh")]
    pub(super) format: crate::TileFormat,
    /// [`TerrainOptions::base`]; absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) base: Option<BaseOptions>,
}

/// A base raster as a plan records it: its path as given and its vertical datum as
/// [`tinsmith_raster::VerticalDatum::parse`] reads it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct BaseOptions {
    pub(super) path: String,
    pub(super) vertical_datum: String,
}

/// Whether `format` is quantized-mesh (which plans leave unsaid).
fn is_quantized_mesh(format: &crate::TileFormat) -> bool {
    *format == crate::TileFormat::QuantizedMesh
}

/// The lattice plans made before the lattice was chosen had.
fn default_cells() -> u32 {
    LATTICE_CELLS[0]
}

/// Whether `cells` is the default (which plans leave unsaid).
fn is_default_cells(cells: &u32) -> bool {
    *cells == LATTICE_CELLS[0]
}

/// Whether `tiling` is the geographic one (which plans leave unsaid).
fn is_geographic(tiling: &Tiling) -> bool {
    *tiling == Tiling::Geographic
}

impl TileOptions {
    /// The options of a run (its `max_zoom` resolved).
    pub(super) fn new(options: &TerrainOptions, max_zoom: u8, cells: u32) -> TileOptions {
        TileOptions {
            band: options.band,
            min_zoom: options.min_zoom,
            max_zoom,
            quality: options.quality,
            normals: options.normals,
            metadata: options.metadata,
            gzip: options.gzip,
            vertical_datum: (options.vertical_datum != tinsmith_raster::VerticalDatum::Ellipsoid)
                .then(|| options.vertical_datum.spec()),
            water: options.water.clone(),
            whole_globe: options.whole_globe,
            tiling: options.tiling,
            cells,
            format: options.format,
            base: options.base.as_ref().map(|base| BaseOptions {
                path: base.path.to_string_lossy().into_owned(),
                vertical_datum: base.vertical_datum.spec(),
            }),
        }
    }

    /// Back to run options, with `threads`.
    pub(super) fn to_options(&self, threads: usize) -> TerrainOptions {
        TerrainOptions {
            band: self.band,
            min_zoom: self.min_zoom,
            max_zoom: Some(self.max_zoom),
            quality: self.quality,
            normals: self.normals,
            metadata: self.metadata,
            gzip: self.gzip,
            threads,
            memory_limit: None,
            update: false,
            vertical_datum: self.vertical_datum.as_deref().map_or(
                tinsmith_raster::VerticalDatum::Ellipsoid,
                tinsmith_raster::VerticalDatum::parse,
            ),
            water: self.water.clone(),
            whole_globe: self.whole_globe,
            format: self.format,
            tiling: self.tiling,
            base: self.base.as_ref().map(|base| crate::BaseRaster {
                path: base.path.clone().into(),
                vertical_datum: tinsmith_raster::VerticalDatum::parse(&base.vertical_datum),
            }),
        }
    }
}

/// A sharded pyramid's plan: the same on every machine for the same input, options and
/// shard count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct Plan {
    /// The input as given (for messages) and its file stem (`layer.json`'s name).
    pub(super) input: String,
    pub(super) name: String,
    /// SHA-256 of the input's size, georeferencing, band type and nodata, and of a
    /// coarse read of its samples; then the same of the base, with one.
    pub(super) fingerprint: String,
    /// `[west, south, east, north, resolution]`, as [`GeoBounds`].
    pub(super) bounds: [f64; 5],
    pub(super) options: TileOptions,
    pub(super) anchor: u8,
    pub(super) split: u8,
    pub(super) shards: u32,
    /// Each block's weight (valid samples of the coarse reads, the input's and the
    /// base's, it holds, plus one), in block order.
    pub(super) weights: Vec<u64>,
}

impl Plan {
    /// The plan for `shards` shards of the pyramid of `input` over `bounds` (anchored at
    /// level `anchor`) with `options` (`max_zoom` resolved).
    pub(super) fn new(
        input: &Path,
        bounds: &GeoBounds,
        anchor: u8,
        options: TileOptions,
        shards: u32,
    ) -> TerrainResult<Plan> {
        // The input, then the base under it: both fingerprinted, both weigh the blocks.
        let mut rasters = vec![(input.to_path_buf(), options.band)];
        if let Some(base) = &options.base {
            rasters.push((base.path.clone().into(), 1));
        }
        let mut hash = Sha256::new();
        let mut centres: Vec<[f64; 2]> = Vec::new();
        let mut cells = 0u64;
        for (path, band) in &rasters {
            let coverage = tinsmith_raster::coverage(path, *band, COVERAGE_SIDE)?;
            let info = tinsmith_raster::WindowReader::open(path, *band)?
                .info()
                .clone();
            let described = serde_json::json!({
                "width": info.width, "height": info.height, "band": info.band,
                "type": info.data_type, "nodata": info.nodata, "scale": info.scale,
                "offset": info.offset, "crs": info.crs_wkt, "transform": info.geo_transform,
            });
            hash.update(described.to_string().as_bytes());
            for v in &coverage.values {
                hash.update(v.to_bits().to_le_bytes());
            }
            centres.extend(
                coverage
                    .centres
                    .iter()
                    .zip(&coverage.values)
                    .filter(|(c, v)| v.is_finite() && c[0].is_finite() && c[1].is_finite())
                    .map(|(&c, _)| c),
            );
            cells += (coverage.width * coverage.height) as u64;
        }
        let fingerprint = hex(&hash.finalize());
        let tiling = Scheme {
            tiling: options.tiling,
            cells: options.cells,
        };
        let (split, weights) = split_and_weights(bounds, tiling, anchor, shards, &centres, cells);
        Ok(Plan {
            input: input.display().to_string(),
            name: input
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "terrain".into()),
            fingerprint,
            bounds: [
                bounds.west,
                bounds.south,
                bounds.east,
                bounds.north,
                bounds.resolution,
            ],
            options,
            anchor,
            split,
            shards,
            weights,
        })
    }

    pub(super) fn bounds(&self) -> GeoBounds {
        let [west, south, east, north, resolution] = self.bounds;
        GeoBounds {
            west,
            south,
            east,
            north,
            resolution,
        }
    }

    /// The tiling and lattice of the plan's tiles.
    pub(super) fn scheme(&self) -> Scheme {
        Scheme {
            tiling: self.options.tiling,
            cells: self.options.cells,
        }
    }

    pub(super) fn cut(&self) -> Cut {
        Cut {
            tiling: self.scheme(),
            anchor: self.anchor,
            split: self.split,
        }
    }

    /// Every block, in block order.
    pub(super) fn blocks(&self) -> Vec<TileRect> {
        blocks(&self.bounds(), self.cut())
    }

    /// The blocks of shard `index`: a run of consecutive blocks, each block going to the
    /// shard whose share of the total weight holds the middle of the block's weight.
    pub(super) fn shard_blocks(&self, index: u32) -> Range<usize> {
        let total: u64 = self.weights.iter().sum();
        let n = u128::from(self.shards);
        let mut before = 0u64;
        let owner: Vec<u32> = self
            .weights
            .iter()
            .map(|&w| {
                let middle = 2 * u128::from(before) + u128::from(w);
                before += w;
                ((middle * n) / (2 * u128::from(total))).min(n - 1) as u32
            })
            .collect();
        let start = owner.partition_point(|&o| o < index);
        let end = owner.partition_point(|&o| o <= index);
        start..end
    }

    /// The hash of the whole plan.
    pub(super) fn id(&self) -> String {
        let text = serde_json::to_string(self).expect("a plan serializes");
        hex(&Sha256::digest(text.as_bytes()))
    }
}

/// Where to cut a pyramid over `bounds` (anchored at `anchor`) for `shards` shards, and
/// each block's weight: one, plus the coarse read's cells with data (`centres`, WGS84
/// longitude and latitude, out of `cells` in all) that fall in it.
///
/// The split is the coarsest level (at most [`crate::blocks::BLOCK_DEPTH`] above the anchor) that gives
/// every shard [`BLOCKS_PER_SHARD`] blocks; then finer while the heaviest block weighs
/// more than a quarter of a shard's share (whole blocks are the unit a shard's share is
/// made of: a land DEM's blocks of sea weigh 1 and of land up to 17) and the coarse read
/// still has 4 cells a block.
pub(super) fn split_and_weights(
    bounds: &GeoBounds,
    tiling: Scheme,
    anchor: u8,
    shards: u32,
    centres: &[[f64; 2]],
    cells: u64,
) -> (u8, Vec<u64>) {
    let lowest = lowest_split(tiling, anchor);
    let cut = |split: u8| Cut {
        tiling,
        anchor,
        split,
    };
    // Splits whose blocks' reach fits their windows (every geographic one from the
    // lowest; a Web Mercator pyramid anchored at level 8 or coarser splits at 0 or near
    // the anchor).
    let fits = |s: &u8| split_fits(tiling, *s, anchor);
    let mut split = (lowest..=anchor)
        .filter(fits)
        .find(|&s| domain(bounds, tiling, s).tiles() >= BLOCKS_PER_SHARD * u64::from(shards))
        .unwrap_or(anchor);
    let mut weights = block_weights(bounds, cut(split), centres);
    while split < anchor && cells >= 4 * domain(bounds, tiling, split + 1).tiles() {
        let total: u64 = weights.iter().sum();
        let heaviest = weights.iter().copied().max().unwrap_or(0);
        if heaviest * 4 * u64::from(shards) <= total {
            break;
        }
        split = (split + 1..=anchor).find(fits).unwrap_or(anchor);
        weights = block_weights(bounds, cut(split), centres);
    }
    (split, weights)
}

/// One plus the points of `centres` (longitude, latitude) in each block of `cut`, in block
/// order.
fn block_weights(bounds: &GeoBounds, cut: Cut, centres: &[[f64; 2]]) -> Vec<u64> {
    let split = cut.split;
    let all = blocks(bounds, cut);
    let index: std::collections::HashMap<(u32, u32), usize> = all
        .iter()
        .enumerate()
        .map(|(k, b)| ((cut.tiling.tile_column(split, b.x0), b.y0), k))
        .collect();
    let mut weights = vec![1u64; all.len()];
    let size = 360.0 / cut.tiling.columns(split) as f64;
    for centre in centres {
        let x = ((centre[0] + 180.0) / size)
            .floor()
            .rem_euclid(cut.tiling.columns(split) as f64);
        let y = match cut.tiling.tiling {
            Tiling::Geographic => ((centre[1] + 90.0) / size).floor(),
            Tiling::Mercator => {
                (tinsmith_raster::web_mercator_y(centre[1]) * (1u64 << split) as f64).floor()
            }
        };
        if y < 0.0 || y >= f64::from(1u32 << split) {
            continue;
        }
        if let Some(&k) = index.get(&(x as u32, y as u32)) {
            weights[k] += 1;
        }
    }
    weights
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_from_0() {
        assert_eq!("3/7".parse::<Shard>(), Ok(Shard { index: 3, count: 7 }));
        for bad in ["7/7", "1/0", "a/2", "3", "-1/2"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    fn plan(weights: Vec<u64>, shards: u32) -> Plan {
        Plan {
            input: String::new(),
            name: String::new(),
            fingerprint: String::new(),
            bounds: [0.0; 5],
            options: TileOptions::new(&TerrainOptions::default(), 3, LATTICE_CELLS[0]),
            anchor: 3,
            split: 1,
            shards,
            weights,
        }
    }

    #[test]
    fn lumpy_weights_cut_finer_until_no_block_outweighs_a_quarter_share() {
        let globe = GeoBounds {
            west: -180.0,
            south: -90.0,
            east: 180.0,
            north: 90.0,
            resolution: 0.05,
        };
        // A coarse read of 128 x 64 cells, one per 2.8 degrees.
        let grid = |keep: &dyn Fn(f64, f64) -> bool| -> Vec<[f64; 2]> {
            (0..64)
                .flat_map(|j| (0..128).map(move |i| (i, j)))
                .map(|(i, j)| {
                    [
                        -180.0 + (i as f64 + 0.5) * 2.8125,
                        -90.0 + (j as f64 + 0.5) * 2.8125,
                    ]
                })
                .filter(|c| keep(c[0], c[1]))
                .collect()
        };
        let cells = 128 * 64;
        // Data everywhere: the coarsest split with 8 blocks a shard (level 2: 32 blocks).
        let (split, weights) =
            split_and_weights(&globe, Scheme::GEOGRAPHIC, 6, 4, &grid(&|_, _| true), cells);
        assert_eq!((split, weights.len()), (2, 32));
        // Data in one corner: finer, until the heaviest block is at most a quarter of a
        // shard's share, or the coarse read has fewer than 4 cells a block.
        let corner = grid(&|lon, lat| lon < -135.0 && lat < -45.0);
        let (split, weights) = split_and_weights(&globe, Scheme::GEOGRAPHIC, 6, 4, &corner, cells);
        // Level 2: one block of 257 in 288; level 3: four of 65 in 384; level 4: sixteen
        // of 17 in 768, and 17 x 4 shards x 4 <= 768.
        let total: u64 = weights.iter().sum();
        assert_eq!((split, weights.iter().max(), total), (4, Some(&17), 768));
        // No finer than the coarse read allows: 4 cells a block (level 4 has 512).
        let (split, _) = split_and_weights(&globe, Scheme::GEOGRAPHIC, 6, 4, &corner, 2047);
        assert_eq!(split, 3);
    }

    #[test]
    fn shards_split_the_weight_into_consecutive_runs() {
        let p = plan(vec![5, 1, 1, 1, 1, 1, 5, 5], 3);
        let runs: Vec<_> = (0..3).map(|i| p.shard_blocks(i)).collect();
        // Thirds of 20 end at 6.7 and 13.3: the blocks' middles are 2.5, 5.5, 6.5 | 7.5,
        // 8.5, 9.5, 13 | 18.
        assert_eq!(runs, [0..3, 3..7, 7..8]);
        // Every block once, in order, whatever the count.
        for n in [1, 2, 5, 8, 64] {
            let p = plan(vec![3; 20], n);
            let mut next = 0;
            for i in 0..n {
                let r = p.shard_blocks(i);
                assert_eq!(r.start, next);
                next = r.end;
            }
            assert_eq!(next, 20);
        }
    }
}
