//! Outdoor lighting (§6.3, §9; `ALGORITHMS.md` §6): the sun and sky models,
//! aerial perspective, sun shadows and sky light on the terrain. The frame's
//! [`crate::view::Lighting`] request becomes per-view GPU constants
//! ([`constants::LightingFrame`], `glsl/include/lighting.glsl`) that every
//! shading pass reads.

pub mod atmosphere;
pub mod constants;
pub mod sky;
