// Horizon maps of the height field (Hoffman's horizon mapping; §9.5): sun
// visibility from the horizon elevation towards the sun's azimuth. The map
// (sky_light.horizon, src/lighting/sky_light/horizon.rs) holds the horizon
// elevation angle (rad) of 16 azimuths φ_j = 2πj/16 (+X towards +Y) per
// height-field texel, in 2×2 tiles of the field's size with 4 azimuths
// (rgba) each: tile t = j / 4 at texel offset ((t & 1)·columns, (t >> 1)·rows).
#ifndef ALPENGLOW_HORIZON_GLSL
#define ALPENGLOW_HORIZON_GLSL

#include "lighting.glsl"

// Horizon elevation (rad) of map azimuth j at continuous texel position t.
float horizon_elevation(uint map, vec2 t, vec2 texels, int j) {
    int tile = j / 4;
    vec2 at = vec2(tile & 1, tile >> 1) * (texels + 1.0) + clamp(t, vec2(0.0), texels) + 0.5;
    vec4 h = textureLod(sampler2D(g_textures[nonuniformEXT(map)], g_samplers[SAMPLER_LINEAR_CLAMP]),
                        at / (2.0 * (texels + 1.0)), 0.0);
    return h[j % 4];
}

// Sun visibility (0..1, softened over the sun's disc) at world point `world`:
// the horizon elevation towards the sun's azimuth (linear between the two
// nearest map azimuths), smoothstep over the disc's angular size.
float horizon_sun_visibility(uint lighting, vec3 world) {
    vec4 field = g_lighting[lighting].f.field;
    vec4 sun = g_lighting[lighting].f.sun;
    uint map = g_lighting[lighting].f.maps.y;
    if (field.z < 1.0 || field.w < 1.0) {
        return 1.0;
    }
    vec2 t = world.xy / field.xy * field.zw;
    float phi = atan(sun.y, sun.x);
    float f = (phi < 0.0 ? phi + 6.28318530717959 : phi) / 6.28318530717959 * 16.0;
    int j0 = int(floor(f)) % 16;
    int j1 = (j0 + 1) % 16;
    float w = fract(f);
    float h = mix(horizon_elevation(map, t, field.zw, j0), horizon_elevation(map, t, field.zw, j1), w);
    float elevation = asin(clamp(sun.z, -1.0, 1.0));
    float radius = max(sun.w, 1e-4);
    return smoothstep(h - radius, h + radius, elevation);
}

#endif
