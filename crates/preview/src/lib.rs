//! Pictures of a raster and its TIN, for people to look at: the raster as a hillshade,
//! the TIN's edges over it, and the signed error TIN − raster as a diverging colour map
//! with a legend that marks the bound.
//!
//! It takes plain slices (the raster's samples, the mesh on the raster's lattice, the
//! TIN's height at each shown sample, [`Scene::surface`])
//! and returns RGBA pixels ([`render`]) or PNG bytes ([`encode_png`]); it reads and writes
//! no file.
//!
//! # Guarantees
//! - The same scene, layers and size give the same pixels and the same PNG bytes (no
//!   time stamp; drawing in `f32` by `tiny-skia` and `ab_glyph`, whose results do not
//!   depend on threads).
//! - The picture's longer side is the size asked for; each pixel shows the sample nearest
//!   its centre ([`DrawnSamples`]: only those samples are needed, so a huge raster is
//!   drawn from a lattice of its samples in memory proportional to the picture).
//! - The wireframe is drawn where the TIN's edges are: an edge from sample `a` to sample
//!   `b` passes through the pixels of the points between them.

mod colour;
mod error;
mod hillshade;
mod legend;
mod png_file;
mod render;

pub use error::PreviewError;
pub use hillshade::hillshade;
pub use png_file::encode_png;
pub use render::{render, DrawnSamples, Layers, Picture, Scene};
