// Sky light on the terrain (§9.3–9.5) from the per-texel sky-light map the
// frame's sky-light pass wrote (SH transfer, AO, patches or the Monte Carlo
// reference). PLACEHOLDER until the sky-light work lands: an open sky of
// the zenith luminance.
#ifndef ALPENGLOW_SKY_LIGHT_GLSL
#define ALPENGLOW_SKY_LIGHT_GLSL

#include "lighting.glsl"
#include "sky.glsl"

// rgb: outgoing radiance per unit albedo from sky light at world point
// `world` with shading normal `normal`; a: sky visibility (1 = open sky).
vec4 sky_light(uint lighting, vec3 world, vec3 normal) {
    return vec4(sky_radiance(lighting, vec3(0.0, 0.0, 1.0)) * (0.5 + 0.5 * normal.z), 1.0);
}

#endif
