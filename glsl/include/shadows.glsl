// Sun visibility (§9.5): cascaded shadow maps (PCF) or horizon maps, by
// models.y. PLACEHOLDER until the shadow work lands: always lit.
#ifndef ALPENGLOW_SHADOWS_GLSL
#define ALPENGLOW_SHADOWS_GLSL

#include "lighting.glsl"

// 0 = in shadow, 1 = lit, filtered, at world point `world` with geometric
// normal `normal`, `view_depth` metres from the camera along its axis.
float sun_visibility(uint lighting, vec3 world, vec3 normal, float view_depth) {
    return 1.0;
}

#endif
