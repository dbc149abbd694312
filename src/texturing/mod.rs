//! Cached procedural textures (dissertation §8.2; `ALGORITHMS.md` §4): a
//! surface-layer tree evaluated on the GPU into tiles of texture atlases,
//! chosen per frame from a quadtree over the height field and reused from
//! frame to frame. Files follow the pipeline of §8.2:
//!
//! * [`layers`]: the surface-layer tree (TOML file, built-in default), hat
//!   functions and coverage, the CPU reference evaluation;
//! * [`input_maps`]: rainfall, radiation and temperature maps registered
//!   to the height field; [`blurred_height`]: the blurred height fields
//!   `height_blur` layers read (snow in furrows);
//! * [`quadtree`]: per frame, the nodes the views need and their tile
//!   sizes, one partition for all views; [`bounds`]: the height field's
//!   per-node bounds it measures;
//! * [`fit`]: the selection coarsened until it fits the atlas;
//! * [`atlas`]: tile slots in the atlases ([`atlas_settings`]: their
//!   layout), least-recently-used eviction, the per-frame generation plan
//!   under a cap;
//! * [`pacing`]: the GPU time budget, from the measured cost per texel;
//! * [`generation`]: the technique: the frame's plan, and the GPU passes that
//!   evaluate the tree into the dirty tiles of a frame, all at once, one
//!   pass per layer (declared by `passes.rs`);
//! * [`page_table`]: the per-frame indirection the terrain shading reads;
//! * [`streaming`]: quadtree, atlas and budget settings, sized from the
//!   frame's views;
//! * [`stats`]: streaming statistics per frame and over a run;
//! * [`from_image`]: surface layers estimated from a real image (§8.3);
//! * [`reference`]: the CPU twin of the shaders' evaluation, for tests;
//! * [`dominant`]: the dominant layer of a point (the class AOV).

pub mod atlas;
pub mod atlas_settings;
pub mod bounds;
pub mod fit;
pub mod from_image;
pub mod generation;
pub mod pacing;
pub mod page_table;
mod passes;
pub mod quadtree;
pub mod reference;
pub mod stats;
pub mod streaming;

#[cfg(test)]
mod tests;
