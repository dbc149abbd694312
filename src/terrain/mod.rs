//! Terrain: procedural height fields (§6.1) and the terrain passes.

pub mod bspline;
pub mod geometry_image;
pub mod importance;
pub mod lod;
pub mod procedural;
pub mod raycast;
pub mod shading;
pub mod sketch_map;
pub mod warp;
pub mod wavelet_noise;
pub mod zoom;
