//! Terrain: procedural height fields (§6.1) and the terrain passes.

pub mod grid;
pub mod importance;
pub mod procedural;
pub mod warp;
