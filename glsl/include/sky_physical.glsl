// The physical atmosphere's sky (Hillaire 2020) from its lookup tables.
// PLACEHOLDER until the atmosphere work lands: the Preetham sky.
#ifndef ALPENGLOW_SKY_PHYSICAL_GLSL
#define ALPENGLOW_SKY_PHYSICAL_GLSL

#include "lighting.glsl"
#include "sky_preetham.glsl"

vec3 physical_sky(uint lighting, vec3 dir) {
    return preetham_sky(lighting, dir);
}

#endif
