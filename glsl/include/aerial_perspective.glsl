// Aerial perspective (§9.1; ALGORITHMS.md §6): extinction and in-scattering
// between the eye and a surface point. PLACEHOLDER until the sky-model work
// lands: no attenuation.
#ifndef ALPENGLOW_AERIAL_PERSPECTIVE_GLSL
#define ALPENGLOW_AERIAL_PERSPECTIVE_GLSL

#include "sky.glsl"

// `color` seen from `eye` at world point `point`.
vec3 aerial_perspective(uint lighting, vec3 color, vec3 eye, vec3 point) {
    return color;
}

#endif
