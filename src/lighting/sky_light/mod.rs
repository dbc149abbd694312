//! Sky light on the terrain (§9.3–9.5; `ALGORITHMS.md` §6), per height-field
//! texel (texel (c, r) at world (c·dx, r·dy, h), normals from central
//! differences):
//!
//! * **Horizon tracing** ([`horizon`], §9.5): for K azimuths, the highest
//!   elevation of the terrain around each texel and where it is; also the
//!   sun **horizon map** (16 azimuths) of Hoffman's horizon mapping,
//!   `horizon_sun_visibility()` in `glsl/include/horizon.glsl`.
//! * **Transfer bake** ([`bake`]): `T_x(ω) = max(0, n·ω) V(x, ω) / π`
//!   projected onto the real SH basis ([`crate::lighting::sh`], 9 or 25
//!   coefficients, §9.3) and onto 8×8 sky patches (§9.5, Fig. 9.6), with 0–2
//!   interreflection bounces (§9.4, eq. 9.9–9.11); sky visibility `1 − O`
//!   and bent normals (eq. 9.18, 9.19).
//! * **Cache** ([`cache`]): a versioned, checksummed file of the bake.
//! * **Per frame** ([`evaluate`]): `lighting.environment` projects the sky
//!   (and optionally the sun) into SH and patch radiances;
//!   `lighting.sky_light` writes the sky-light map by mode (rgb: outgoing
//!   radiance per unit albedo, a: sky visibility), read by `sky_light()` in
//!   `glsl/include/sky_light.glsl`.
//!
//! ```text
//! let bake = SkyLightBake::bake(&ctx, &field, &BakeSettings::from_lighting(&lighting), cache_dir, &mut |f| bar.set(f))?;
//! let sky_light = SkyLight::new(&ctx, bake)?;
//! let ids = sky_light.declare(&mut graph, lighting_region, &atmosphere_luts);   // passes read ids.map, ids.horizon, ids.environment
//! sky_light.fill(&mut lighting_frame);                                          // field (the handles: the `sky` pass)
//! ```

pub mod bake;
pub mod cache;
pub mod evaluate;
pub mod fit;
pub mod horizon;
mod tables;

pub use bake::{BakeSettings, SkyLightBake};
pub use evaluate::SkyLight;

/// Sky patches per side baked (the 4×4 patches merge 2×2 of them).
pub const PATCHES_PER_SIDE: u32 = 8;
/// Azimuths of the sun horizon map.
pub const HORIZON_MAP_AZIMUTHS: u32 = 16;
/// Floats per texel of the surface buffer: normal, sky visibility, bent normal, unused.
pub const SURFACE_FLOATS: u32 = 8;
/// Length (vec4) of the environment buffer: 25 SH (rgb), 64 + 16 patch radiances.
pub const ENVIRONMENT_VEC4S: u32 = 25 + 64 + 16;
