// The per-view lighting constants every shading pass reads (§6.3, §9;
// src/lighting/constants.rs, LightingFrame): sun, sky model coefficients,
// aerial perspective, shadow cascades, sky-light maps, exposure. One
// struct per view in the frame's upload arena, bound by a storage handle.
#ifndef ALPENGLOW_LIGHTING_GLSL
#define ALPENGLOW_LIGHTING_GLSL

#include "heap.glsl"

#define MAX_CASCADES 4

// models.x
const uint SKY_PREETHAM = 0u;
const uint SKY_PHYSICAL = 1u;
// models.y
const uint SHADOWS_OFF = 0u;
const uint SHADOWS_CASCADED = 1u;
const uint SHADOWS_HORIZON = 2u;
// models.z
const uint SKY_LIGHT_OFF = 0u;
const uint SKY_LIGHT_REFERENCE = 1u;
const uint SKY_LIGHT_SH = 2u;
const uint SKY_LIGHT_AO = 3u;
const uint SKY_LIGHT_PATCHES = 4u;
// models.w: flags
const uint LIGHTING_SUN_IN_ENVIRONMENT = 1u;  // the sun is part of the sky-light environment (figures)
const uint LIGHTING_ALBEDO_OVERRIDE = 2u;     // every surface has albedo exposure.w
const uint LIGHTING_NO_SUN_DIRECT = 4u;       // no direct sun term (sky light only)
const uint LIGHTING_NO_AERIAL_PERSPECTIVE = 8u;
const uint LIGHTING_SOFT_SUN = 16u;           // sun shadows with the disc's penumbra (shadows.glsl)

struct LightingFrame {
    vec4 sun;              // xyz: unit vector towards the sun (+Z up); w: angular radius of the disc (rad)
    vec4 sun_radiance;     // rgb: radiance of the disc centre at the ground (linear sRGB, luminance in cd/m²); w: limb darkening u
    vec4 sun_irradiance;   // rgb: irradiance of the whole disc on a plane facing the sun (same units × sr); w: unused
    vec4 perez[5];         // Perez A..E; xyz: for Y, x, y (Preetham)
    vec4 zenith;           // x: Y_z (cd/m²), y: x_z, z: y_z (Preetham); w: turbidity
    vec4 perez_norm;       // xyz: 1 / F(0, θ_s) for Y, x, y
    vec4 rayleigh;         // rgb: β_R at the ground (1/m); w: Henyey–Greenstein g of Mie
    vec4 mie;              // rgb: β_M at the ground (1/m); w: altitude of the ground (m) for the atmosphere
    vec4 planet;           // x: bottom radius (m), y: top radius (m), z: Rayleigh scale height (m), w: Mie scale height (m)
    vec4 exposure;         // x: manual exposure multiplier (0: automatic), y: EV100 compensation, z: snow line (m), w: albedo override
    vec4 field;            // xy: height field extent (m) (texel centres 0..extent), zw: texel count - 1 (columns, rows)
    uvec4 models;          // x: sky model, y: shadows, z: sky light, w: flags
    uvec4 atmosphere;      // sampled handles: x transmittance LUT, y multiple-scattering LUT, z sky-view LUT; w: unused
    uvec4 maps;            // x: sky-light map (sampled; rgb: sky light per unit albedo, a: sky visibility),
                           // y: horizon map (sampled), z: sun-visibility map of the reference (sampled), w: environment (storage)
    uvec4 shadows;         // x: shadow atlas (sampled depth), y: cascade count, z: atlas size (texels), w: PCF radius (texels)
    mat4 cascade_view_proj[MAX_CASCADES];  // world → the cascade's clip space (xy already mapped to its atlas quadrant)
    vec4 cascade_far;      // view depth (m) where each cascade ends
    vec4 cascade_texel;    // world size (m) of one shadow texel per cascade
};

layout(set = 0, binding = 2, std430) readonly buffer LightingFrames { LightingFrame f; } g_lighting[];

#endif
