//! 3D Tiles 1.1 terrain layout: `tileset.json` (a root whose two children are the
//! geographic root tiles, each an implicit quadtree) and the binary subtrees that say
//! which tiles exist and carry each tile's metadata (`TILE_MINIMUM_HEIGHT`,
//! `TILE_MAXIMUM_HEIGHT`, `TILE_BOUNDING_SPHERE`, `TILE_HORIZON_OCCLUSION_POINT`), as
//! CesiumJS's `Cesium3DTilesTerrainProvider` reads them.
//!
//! Tile `z/x/y` of the TMS pyramid (y = 0 in the south) is, in implicit coordinates, tile
//! `(z, x mod 2^z, y)` of root `x / 2^z` (CesiumJS's
//! `getImplicitTileCoordinatesFromGeographicCoordinates`); its GLB is
//! `tiles/{root}/{z}/{x mod 2^z}/{y}.glb`.

use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI};

use serde_json::json;

use crate::glb_tile::TileBounds;
use crate::LEVEL_ZERO_ERROR;

/// The most levels per subtree: a subtree file then holds the availability and metadata
/// of 8 levels (up to 21,845 tiles, 2.7 KB of availability bits) and says which of the
/// 65,536 subtrees below it exist (8 KB of bits, or a constant when none does).
pub const MAX_SUBTREE_LEVELS: u8 = 8;

/// Levels per subtree in a pyramid whose deepest level is `max_level`: all of them up to
/// [`MAX_SUBTREE_LEVELS`], so that a small pyramid is two subtree files, not one per tile
/// of its last level.
pub(super) fn subtree_levels(max_level: u8) -> u8 {
    (max_level + 1).min(MAX_SUBTREE_LEVELS)
}

/// The metadata class of every tile.
const TILE_CLASS: &str = "tile";

/// Each tile's metadata, by TMS address.
pub(super) type TileMetadata = BTreeMap<(u8, u32, u32), TileBounds>;

/// A file to write: its name and bytes.
type File = (String, Vec<u8>);

/// Root (0: west, 1: east) and implicit column of TMS tile column `x` of level `z`.
fn implicit(z: u8, x: u32) -> (u32, u32) {
    (x >> z, x & ((1u32 << z) - 1))
}

/// The name of the GLB of TMS tile `z/x/y`.
pub(super) fn tile_path(z: u8, x: u32, y: u32) -> String {
    let (root, ix) = implicit(z, x);
    format!("tiles/{root}/{z}/{ix}/{y}.glb")
}

/// The name of the subtree of `root` whose root tile is implicit `level/x/y`.
fn subtree_path(root: u32, level: u8, x: u32, y: u32) -> String {
    format!("subtrees/{root}/{level}/{x}/{y}.subtree")
}

/// The Morton index of local tile `x`, `y` (x in the even bits).
fn morton(x: u32, y: u32) -> u64 {
    let spread = |v: u32| {
        let mut v = u64::from(v);
        v = (v | (v << 16)) & 0x0000_FFFF_0000_FFFF;
        v = (v | (v << 8)) & 0x00FF_00FF_00FF_00FF;
        v = (v | (v << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    };
    spread(x) | (spread(y) << 1)
}

/// The text of `tileset.json` for tiles down to `max_level` whose metadata is `tiles`.
pub(super) fn tileset_json(tiles: &TileMetadata, max_level: u8) -> String {
    let levels = subtree_levels(max_level);
    let (lo, hi) = tiles.values().fold((0.0f64, 0.0f64), |(lo, hi), t| {
        (lo.min(t.min_height), hi.max(t.max_height))
    });
    let scalar = |semantic: &str| json!({"type": "SCALAR", "componentType": "FLOAT64", "semantic": semantic});
    let schema = json!({
        "id": "tinsmith_terrain",
        "classes": {TILE_CLASS: {"properties": {
            "minimumHeight": scalar("TILE_MINIMUM_HEIGHT"),
            "maximumHeight": scalar("TILE_MAXIMUM_HEIGHT"),
            "boundingSphere": {"type": "SCALAR", "componentType": "FLOAT64", "array": true,
                               "count": 4, "semantic": "TILE_BOUNDING_SPHERE"},
            "horizonOcclusionPoint": {"type": "VEC3", "componentType": "FLOAT64",
                                      "semantic": "TILE_HORIZON_OCCLUSION_POINT"},
        }}},
    });
    let child = |root: u32| {
        let west = -PI + f64::from(root) * PI;
        json!({
            "boundingVolume": {"region": [west, -FRAC_PI_2, west + PI, FRAC_PI_2, lo, hi]},
            "geometricError": LEVEL_ZERO_ERROR,
            "refine": "REPLACE",
            "content": {"uri": format!("tiles/{root}/{{level}}/{{x}}/{{y}}.glb")},
            "implicitTiling": {
                "subdivisionScheme": "QUADTREE",
                "subtreeLevels": levels,
                "availableLevels": u32::from(max_level) + 1,
                "subtrees": {"uri": format!("subtrees/{root}/{{level}}/{{x}}/{{y}}.subtree")},
            },
        })
    };
    let tileset = json!({
        "asset": {"version": "1.1", "generator": "tinsmith"},
        "schema": schema,
        "geometricError": 2.0 * LEVEL_ZERO_ERROR,
        "root": {
            "boundingVolume": {"region": [-PI, -FRAC_PI_2, PI, FRAC_PI_2, lo, hi]},
            "geometricError": 2.0 * LEVEL_ZERO_ERROR,
            "refine": "REPLACE",
            "children": [child(0), child(1)],
        },
    });
    serde_json::to_string_pretty(&tileset).expect("JSON values serialize")
}

/// One subtree being gathered: its available tiles (bit index -> metadata) and child
/// subtrees (bit index).
#[derive(Default)]
struct Subtree {
    tiles: BTreeMap<u64, TileBounds>,
    children: Vec<u64>,
}

/// Every subtree file (name, bytes) of the tiles in `tiles`, `s` levels each, whose
/// parents are all in `tiles` too (a tile without its parent could not be reached).
///
/// # Errors
/// The address of a tile whose parent is missing.
pub(super) fn subtrees(tiles: &TileMetadata, s: u8) -> Result<Vec<File>, (u8, u32, u32)> {
    let mut by_root: BTreeMap<(u32, u8, u32, u32), Subtree> = BTreeMap::new();
    for (&(z, x, y), &bounds) in tiles {
        if z > 0 && !tiles.contains_key(&(z - 1, x / 2, y / 2)) {
            return Err((z, x, y));
        }
        let (root, ix) = implicit(z, x);
        let base = z / s * s;
        let local = z - base;
        let key = (root, base, ix >> local, y >> local);
        let mask = (1u32 << local) - 1;
        let first = ((1u64 << (2 * local)) - 1) / 3;
        let bit = first + morton(ix & mask, y & mask);
        by_root.entry(key).or_default().tiles.insert(bit, bounds);
        if local == 0 && base > 0 {
            // A child subtree of the subtree `s` levels up.
            let parent = (root, base - s, ix >> s, y >> s);
            let mask = (1u32 << s) - 1;
            by_root
                .entry(parent)
                .or_default()
                .children
                .push(morton(ix & mask, y & mask));
        }
    }
    Ok(by_root
        .into_iter()
        .map(|((root, level, x, y), subtree)| {
            (subtree_path(root, level, x, y), subtree_bytes(&subtree, s))
        })
        .collect())
}

/// The binary subtree (`subt`, version 1) of `subtree`.
fn subtree_bytes(subtree: &Subtree, levels: u8) -> Vec<u8> {
    let s = u32::from(levels);
    let tile_bits = ((1u64 << (2 * s)) - 1) / 3;
    let child_bits = 1u64 << (2 * s);
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut view = |bin: &mut Vec<u8>, data: Vec<u8>| {
        let offset = bin.len();
        bin.extend_from_slice(&data);
        bin.resize(bin.len().next_multiple_of(8), 0);
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": data.len()}));
        views.len() - 1
    };
    let bitstream = |bits: u64, set: &mut dyn Iterator<Item = u64>| {
        let mut bytes = vec![0u8; bits.div_ceil(8) as usize];
        for b in set {
            bytes[(b / 8) as usize] |= 1 << (b % 8);
        }
        bytes
    };
    let available = bitstream(tile_bits, &mut subtree.tiles.keys().copied());
    let count = subtree.tiles.len();
    let tile_view = view(&mut bin, available);
    let tile_availability = json!({"bitstream": tile_view, "availableCount": count});
    let child_availability = if subtree.children.is_empty() {
        json!({"constant": 0})
    } else {
        let bits = bitstream(child_bits, &mut subtree.children.iter().copied());
        let v = view(&mut bin, bits);
        json!({"bitstream": v, "availableCount": subtree.children.len()})
    };
    let values = |f: &dyn Fn(&TileBounds) -> Vec<f64>| -> Vec<u8> {
        subtree
            .tiles
            .values()
            .flat_map(f)
            .flat_map(f64::to_le_bytes)
            .collect()
    };
    let min = view(&mut bin, values(&|t| vec![t.min_height]));
    let max = view(&mut bin, values(&|t| vec![t.max_height]));
    let sphere = view(&mut bin, values(&|t| t.sphere.to_vec()));
    let hop = view(&mut bin, values(&|t| t.horizon_occlusion_point.to_vec()));
    let document = json!({
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "propertyTables": [{
            "class": TILE_CLASS,
            "count": count,
            "properties": {
                "minimumHeight": {"values": min},
                "maximumHeight": {"values": max},
                "boundingSphere": {"values": sphere},
                "horizonOcclusionPoint": {"values": hop},
            },
        }],
        "tileAvailability": tile_availability,
        "contentAvailability": [tile_availability],
        "childSubtreeAvailability": child_availability,
        "tileMetadata": 0,
    });
    let mut text = serde_json::to_vec(&document).expect("subtree JSON serializes");
    text.resize(text.len().next_multiple_of(8), b' ');
    let mut out = Vec::with_capacity(24 + text.len() + bin.len());
    out.extend_from_slice(b"subt");
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&(text.len() as u64).to_le_bytes());
    out.extend_from_slice(&(bin.len() as u64).to_le_bytes());
    out.extend_from_slice(&text);
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds(h: f64) -> TileBounds {
        TileBounds {
            min_height: h,
            max_height: h + 1.0,
            sphere: [1.0, 2.0, 3.0, 4.0],
            horizon_occlusion_point: [0.5, 0.5, 0.5],
        }
    }

    #[test]
    fn morton_interleaves_x_in_the_even_bits() {
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(3, 3), 15);
        assert_eq!(morton(2, 1), 6);
    }

    #[test]
    fn the_east_root_tiles_are_numbered_from_its_west_edge() {
        assert_eq!(tile_path(0, 1, 0), "tiles/1/0/0/0.glb");
        assert_eq!(tile_path(2, 5, 3), "tiles/1/2/1/3.glb");
        assert_eq!(tile_path(2, 3, 0), "tiles/0/2/3/0.glb");
    }

    #[test]
    fn deep_tiles_open_child_subtrees_and_orphans_are_refused() {
        let mut tiles = TileMetadata::new();
        // A chain from root 1 down to level S, along the south-west corner.
        const S: u8 = 3;
        for z in 0..=S {
            tiles.insert((z, 1 << z, 0), bounds(f64::from(z)));
        }
        tiles.insert((0, 0, 0), bounds(0.0));
        let files = subtrees(&tiles, S).unwrap();
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "subtrees/0/0/0/0.subtree".to_string(),
                "subtrees/1/0/0/0.subtree".to_string(),
                format!("subtrees/1/{S}/0/0.subtree"),
            ]
        );
        let root1 = &files[1].1;
        assert_eq!(&root1[..4], b"subt");
        let json_length = u64::from_le_bytes(root1[8..16].try_into().unwrap()) as usize;
        let doc: serde_json::Value = serde_json::from_slice(&root1[24..24 + json_length]).unwrap();
        assert_eq!(doc["propertyTables"][0]["count"], u64::from(S));
        assert_eq!(doc["childSubtreeAvailability"]["availableCount"], 1);
        tiles.insert((3, 7, 7), bounds(0.0));
        assert_eq!(subtrees(&tiles, S).unwrap_err(), (3, 7, 7));
        assert_eq!(subtree_levels(4), 5);
        assert_eq!(subtree_levels(15), MAX_SUBTREE_LEVELS);
    }
}
