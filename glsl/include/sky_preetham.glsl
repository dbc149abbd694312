// The Preetham/Perez sky (§6.3; ALGORITHMS.md §6). PLACEHOLDER until the
// sky-model work lands: a constant-luminance zenith colour.
#ifndef ALPENGLOW_SKY_PREETHAM_GLSL
#define ALPENGLOW_SKY_PREETHAM_GLSL

#include "lighting.glsl"

vec3 preetham_sky(uint lighting, vec3 dir) {
    return vec3(0.5, 0.7, 1.0) * g_lighting[lighting].f.zenith.x;
}

#endif
