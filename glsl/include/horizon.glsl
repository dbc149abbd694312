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

// The fraction of a uniform disc of radius 1 above a straight horizon at
// signed distance x below its centre (x = −1: hidden, 1: whole): the
// circular segment's area over π, 1/2 + (x·sqrt(1−x²) + asin x)/π.
float sun_disc_fraction(float x) {
    x = clamp(x, -1.0, 1.0);
    return 0.5 + (x * sqrt(max(1.0 - x * x, 0.0)) + asin(x)) / 3.14159265358979;
}

// Sun visibility (0..1) at world point `world`: the horizon elevation h
// towards the sun's azimuth (linear between the two nearest map azimuths)
// against the sun's elevation e. With LIGHTING_SOFT_SUN the fraction of the
// sun's disc (angular radius r) above the horizon, exact for a straight
// horizon across the disc: sun_disc_fraction((e − h) / r); else a
// smoothstep over the disc's angular size.
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
    if ((g_lighting[lighting].f.models.w & LIGHTING_SOFT_SUN) != 0u) {
        return sun_disc_fraction((elevation - h) / radius);
    }
    return smoothstep(h - radius, h + radius, elevation);
}

#endif
