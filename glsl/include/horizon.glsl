// Horizon maps of the height field (Hoffman; §9.5): sun visibility from the
// horizon elevation towards the sun's azimuth. PLACEHOLDER until the
// sky-light work lands: always lit.
#ifndef ALPENGLOW_HORIZON_GLSL
#define ALPENGLOW_HORIZON_GLSL

#include "lighting.glsl"

// Sun visibility (0..1, softened over the sun's disc) at world point `world`.
float horizon_sun_visibility(uint lighting, vec3 world) {
    return 1.0;
}

#endif
