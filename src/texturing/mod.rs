//! Cached procedural textures (dissertation §8.2; `ALGORITHMS.md` §4): a
//! surface-layer tree evaluated on the GPU into tiles of texture atlases,
//! chosen per frame from a quadtree over the height field and reused from
//! frame to frame. Files follow the pipeline of §8.2:
//!
//! * the surface material it evaluates is shared with the terrain and the
//!   vegetation, in `crate::surface`: the layer tree (`surface::layers`),
//!   its input maps and blurred height fields (`surface::input_maps`,
//!   `surface::blurred_height`), the layers buffer (`surface::gpu_layout`)
//!   and the dominant layer of a point (`surface::dominant`, the class AOV);
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
//! * [`reference`]: the CPU twin of the shaders' evaluation, for tests.

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
