//! Terrain: procedural height fields (§6.1) and the terrain passes.

pub mod procedural;
pub mod grid;
