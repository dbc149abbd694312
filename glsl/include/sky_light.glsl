// Sky light on the terrain (§9.3–9.5) from the per-texel sky-light map the
// frame's lighting.sky_light pass wrote (SH transfer, AO with bent normals,
// sky patches, unoccluded; src/lighting/sky_light) or the Monte Carlo
// reference: rgb = outgoing radiance per unit albedo, a = sky visibility.
// The map is per height-field texel (its normal from the field's central
// differences); the shading normal is not used.
#ifndef ALPENGLOW_SKY_LIGHT_GLSL
#define ALPENGLOW_SKY_LIGHT_GLSL

#include "lighting.glsl"

// rgb: outgoing radiance per unit albedo from sky light at world point
// `world` (bilinear between the texels around world.xy); a: sky visibility
// (1 = open sky).
vec4 sky_light(uint lighting, vec3 world, vec3 normal) {
    vec4 field = g_lighting[lighting].f.field;
    uint map = g_lighting[lighting].f.maps.x;
    vec2 texels = max(field.zw, vec2(1.0));
    vec2 uv = (world.xy / max(field.xy, vec2(1e-6)) * field.zw + 0.5) / (texels + 1.0);
    return textureLod(sampler2D(g_textures[nonuniformEXT(map)], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0);
}

#endif
