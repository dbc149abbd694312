//! The per-view lighting constants (`glsl/include/lighting.glsl`,
//! `LightingFrame`): the lighting technique's prepare step computes their
//! values, and the view's `sky` pass, which declares every lighting map,
//! adds the maps' heap handles and writes them into the frame's upload
//! arena; every shading pass reads them through one storage handle.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::graph::PassContext;
use crate::view::{LightingBindings, LightingMap};

/// Angular radius of the sun's disc (rad).
pub const SUN_ANGULAR_RADIUS: f32 = 0.004_654;
/// Luminance of the sun's disc above the atmosphere (cd/m²), the absolute
/// scale every sky model shares.
pub const SUN_LUMINANCE_EXTRATERRESTRIAL: f32 = 1.96e9;
/// Colour of the sun above the atmosphere in linear sRGB (luminance 1).
pub const SUN_COLOUR_EXTRATERRESTRIAL: [f32; 3] = [1.0602, 0.9889, 0.9330];

/// Shadow cascades, at most.
pub const MAX_CASCADES: usize = 4;

/// `models.x`.
pub const SKY_PREETHAM: u32 = 0;
pub const SKY_PHYSICAL: u32 = 1;
/// `models.y`.
pub const SHADOWS_OFF: u32 = 0;
pub const SHADOWS_CASCADED: u32 = 1;
pub const SHADOWS_HORIZON: u32 = 2;
/// `models.z`.
pub const SKY_LIGHT_OFF: u32 = 0;
pub const SKY_LIGHT_REFERENCE: u32 = 1;
pub const SKY_LIGHT_SH: u32 = 2;
pub const SKY_LIGHT_AO: u32 = 3;
pub const SKY_LIGHT_PATCHES: u32 = 4;
/// `models.w` flags.
pub const LIGHTING_SUN_IN_ENVIRONMENT: u32 = 1;
pub const LIGHTING_ALBEDO_OVERRIDE: u32 = 2;
pub const LIGHTING_NO_SUN_DIRECT: u32 = 4;
pub const LIGHTING_NO_AERIAL_PERSPECTIVE: u32 = 8;
/// Sun shadows with the penumbra of the sun's disc ([`crate::view::SunDisc::Soft`]).
pub const LIGHTING_SOFT_SUN: u32 = 16;

/// One view's lighting constants (std430, field for field as in GLSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct LightingFrame {
    /// xyz: unit vector towards the sun; w: angular radius (rad).
    pub sun: [f32; 4],
    /// rgb: radiance of the disc centre at the ground (cd/m²-scaled linear sRGB); w: limb darkening u.
    pub sun_radiance: [f32; 4],
    /// rgb: irradiance of the whole disc on a plane facing the sun.
    pub sun_irradiance: [f32; 4],
    /// Perez A..E; xyz for Y, x, y.
    pub perez: [[f32; 4]; 5],
    /// x: Y_z (cd/m²), y: x_z, z: y_z; w: turbidity.
    pub zenith: [f32; 4],
    /// xyz: 1 / F(0, θ_s) for Y, x, y; w: 1 for the CIE overcast sky's
    /// luminance `Y_z (1 + 2 cos θ) / 3` instead of the Perez one (§6.3).
    pub perez_norm: [f32; 4],
    /// rgb: β_R at the ground (1/m); w: Mie g.
    pub rayleigh: [f32; 4],
    /// rgb: β_M at the ground (1/m); w: ground altitude (m).
    pub mie: [f32; 4],
    /// Bottom radius, top radius, Rayleigh and Mie scale heights (m).
    pub planet: [f32; 4],
    /// x: manual exposure multiplier (0: automatic), y: EV100 compensation,
    /// z: snow line (m), w: albedo override.
    pub exposure: [f32; 4],
    /// xy: height field extent (m); zw: columns − 1, rows − 1.
    pub field: [f32; 4],
    /// Sky model, shadows, sky light, flags.
    pub models: [u32; 4],
    /// Sampled handles: transmittance, multiple scattering, sky view LUTs.
    pub atmosphere: [u32; 4],
    /// Sampled handles: sky-light map, horizon map, reference sun
    /// visibility; storage handle of the environment.
    pub maps: [u32; 4],
    /// Shadow atlas (sampled), cascade count, atlas size, PCF radius.
    pub shadows: [u32; 4],
    /// World → cascade clip space, column-major.
    pub cascade_view_proj: [[f32; 16]; MAX_CASCADES],
    /// View depth (m) where each cascade ends.
    pub cascade_far: [f32; 4],
    /// World size (m) of one shadow texel per cascade.
    pub cascade_texel: [f32; 4],
}

impl LightingFrame {
    /// Writes `handle`, the heap handle of the lighting map `map`, into its
    /// slot. The reference's maps replace the sky-light map only in the
    /// reference mode (`models.z`, set first).
    pub fn set_map_handle(&mut self, map: LightingMap, handle: u32) {
        let reference = self.models[2] == SKY_LIGHT_REFERENCE;
        match map {
            LightingMap::Transmittance => self.atmosphere[0] = handle,
            LightingMap::Multiscattering => self.atmosphere[1] = handle,
            LightingMap::SkyView => self.atmosphere[2] = handle,
            LightingMap::ShadowAtlas => self.shadows[0] = handle,
            LightingMap::SkyLight if !reference => self.maps[0] = handle,
            LightingMap::Horizon => self.maps[1] = handle,
            LightingMap::Environment => self.maps[3] = handle,
            LightingMap::ReferenceSkyLight if reference => self.maps[0] = handle,
            LightingMap::ReferenceSunVisibility if reference => self.maps[2] = handle,
            LightingMap::SkyLight | LightingMap::ReferenceSkyLight | LightingMap::ReferenceSunVisibility => {}
        }
    }

    /// Writes the heap handles of every lighting map `bindings` holds (the
    /// declarations of the pass recording, `ctx`).
    pub fn set_map_handles(&mut self, ctx: &PassContext<'_>, bindings: &LightingBindings) -> Result<()> {
        for &(map, binding) in &bindings.maps {
            self.set_map_handle(map, ctx.handle(binding)?);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extraterrestrial_colour_has_unit_luminance() {
        let [r, g, b] = SUN_COLOUR_EXTRATERRESTRIAL;
        assert!((0.2126 * r + 0.7152 * g + 0.0722 * b - 1.0).abs() < 1e-3);
    }

    #[test]
    fn layout_matches_std430() {
        // 19 vec4/uvec4 rows before the matrices, 4 mat4, 2 vec4.
        assert_eq!(std::mem::size_of::<LightingFrame>(), (19 + 4 * 4 + 2) * 16);
    }
}
