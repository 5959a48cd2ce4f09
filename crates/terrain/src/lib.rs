//! Cesium quantized-mesh terrain: the tile encoder ([`QuantizedMeshTile`]) and whole
//! pyramids ([`build_terrain`]): geographic TMS tiles (EPSG:4326, 2x1 root tiles, y = 0
//! in the south) or Web Mercator ones ([`Tiling::Mercator`], EPSG:3857, 1x1), each
//! decimated within `quality x e(level)` (Cesium's geometric error at the level for the
//! tiling) and checked by the independent verifier, with shared edges simplified once
//! so that same-level neighbours keep identical edge vertices, and `layer.json` with the
//! tiles' availability. The pyramid is staged and moved into place whole. The same tiles
//! can be written as 3D Tiles 1.1 terrain instead ([`TileFormat::ThreeDTiles`]: one GLB per
//! tile, [`GlbTile`], implicit subtrees and `tileset.json`). A [`BaseRaster`] under the
//! input fills every lattice point where the input has no valid sample.

mod base;
mod blocks;
mod budget;
mod error;
mod glb_tile;
mod globe_edges;
mod implicit;
mod layer;
mod order;
mod plan;
mod pyramid;
mod quantized_mesh;
mod records;
mod rows;
mod shards;
mod stream;
mod tile;
mod tms;
mod water;
mod writer;

pub use base::BaseRaster;
pub use budget::LEVEL_ZERO_ERROR;
pub use error::{TerrainError, TerrainResult};
pub use glb_tile::{GlbTile, TileBounds, TILE_EDGES_EXTENSION};
pub use implicit::MAX_SUBTREE_LEVELS;
pub use layer::METADATA_AVAILABILITY;
pub use plan::Shard;
pub use pyramid::{
    build_terrain, build_terrain_in, streaming_bytes, LevelReport, Progress, TerrainOptions,
    TerrainReport, TileFormat, MAX_LEVEL,
};
pub use quantized_mesh::{
    geodetic_to_ecef, gzip, oct_encode, surface_normal, EncodeError, GeoRectangle,
    QuantizedMeshTile, EXTENSION_METADATA, EXTENSION_NORMALS, HEADER_BYTES, MAX_16BIT_VERTICES,
    QUANTIZED_MAX, WGS84_A, WGS84_B,
};
pub use shards::{build_shard, merge_shards, ShardReport};
pub use tms::{lattice_cells, tile_rectangle, Scheme, Tiling, LATTICE_CELLS};
pub use water::{Water, MASK_CELLS};
