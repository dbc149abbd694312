//! Outdoor lighting (§6.3, §9; `ALGORITHMS.md` §6): the sun and sky models,
//! aerial perspective, sun shadows and sky light on the terrain. The frame's
//! [`crate::view::Lighting`] request becomes per-view GPU constants
//! ([`constants::LightingFrame`], `glsl/include/lighting.glsl`) that every
//! shading pass reads.

pub mod aerial;
pub mod atmosphere;
pub mod constants;
pub mod preetham;
pub mod reference;
pub mod sh;
#[cfg(test)]
pub(crate) mod sh_bands;
pub mod shadows;
pub mod sky;
pub mod sky_light;
pub mod solar;
pub mod technique;

#[cfg(test)]
mod tests;
