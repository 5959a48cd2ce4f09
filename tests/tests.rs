//! End-to-end tests of the `tinsmith` binary: one temp dir per test, the real binary.

mod util;

mod bad_input;
mod base;
mod breaklines;
mod cesium;
mod cli_reference;
mod contour;
mod dask;
mod foreign;
mod formats;
mod mbtiles;
mod mesh_and_verify;
mod object_storage;
mod ogr_points;
mod points;
mod preview;
mod serve;
mod shards;
mod threedtiles;
mod tiled_mesh;
mod tiled_variables;
mod tiles;
mod tin_input;
mod variables;
