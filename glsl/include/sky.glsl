// Sky radiance by model (§6.3; ALGORITHMS.md §6): the Preetham/Perez sky
// (sky_preetham.glsl) or the physical atmosphere's lookup tables
// (sky_physical.glsl), chosen per frame by models.x. Absolute units:
// linear sRGB whose luminance Y = 0.2126 R + 0.7152 G + 0.0722 B is in cd/m².
#ifndef ALPENGLOW_SKY_GLSL
#define ALPENGLOW_SKY_GLSL

#include "lighting.glsl"
#include "sky_preetham.glsl"
#include "sky_physical.glsl"

// Sky radiance along unit direction `dir` (+Z up), without the sun disc.
// Below the horizon, where no terrain was drawn, both models show the same
// stand-in for the ground: the horizon's radiance darkened smoothly
// (preetham_ground_factor), so a scene without terrain is not lit by, or
// exposed for, a black lower hemisphere.
vec3 sky_radiance(uint lighting, vec3 dir) {
    if (g_lighting[lighting].f.models.x == SKY_PHYSICAL) {
        if (dir.z >= 0.0) {
            return physical_sky(lighting, dir);
        }
        vec2 h = length(dir.xy) > 1e-6 ? normalize(dir.xy) : vec2(0.0, 1.0);
        vec3 horizon = physical_sky(lighting, vec3(h * 0.99995, 0.01));
        return horizon * preetham_ground_factor(dir.z);
    }
    return preetham_sky(lighting, dir);
}

// Radiance of the sun disc along `dir` (0 outside the disc), limb-darkened.
vec3 sun_disc_radiance(uint lighting, vec3 dir) {
    vec4 sun = g_lighting[lighting].f.sun;
    float cos_gamma = dot(dir, sun.xyz);
    float cos_radius = cos(sun.w);
    if (cos_gamma < cos_radius || sun.z < -sun.w) {
        return vec3(0.0);
    }
    // Limb darkening: I(r) = 1 − u (1 − sqrt(1 − r²)), r = γ / radius.
    float r = clamp(acos(clamp(cos_gamma, -1.0, 1.0)) / sun.w, 0.0, 1.0);
    float u = g_lighting[lighting].f.sun_radiance.w;
    return g_lighting[lighting].f.sun_radiance.rgb * (1.0 - u * (1.0 - sqrt(1.0 - r * r)));
}

#endif
