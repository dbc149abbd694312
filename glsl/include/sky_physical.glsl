// The physical atmosphere's sky (Hillaire 2020 §5.3; beyond the
// dissertation, whose sky is Preetham's, §6.3, §9.1): the radiance along a
// direction from the view's sky-view table (atmosphere_physical.glsl,
// lighting.sky_view), computed for the camera's altitude above the ground
// level. Linear sRGB, luminance in cd/m²; no sun disc. Below the horizon:
// the table's lower half, the light scattered between the camera and the
// ground (not the ground itself).
#ifndef ALPENGLOW_SKY_PHYSICAL_GLSL
#define ALPENGLOW_SKY_PHYSICAL_GLSL

#include "atmosphere_physical.glsl"

vec3 physical_sky(uint lighting, vec3 dir) {
    LightingFrame f = g_lighting[lighting].f;
    float len = length(dir);
    if (!(len > 0.0) || isinf(len)) {
        return vec3(0.0);
    }
    dir /= len;
    Atmosphere a;
    a.bottom = f.planet.x * 1e-3;
    a.top = max(f.planet.y * 1e-3, a.bottom + 1.0);
    float r = a.bottom + atmosphere_camera_altitude(lighting, a);
    // Azimuth from the sun's: the table covers 0..π (symmetric sky).
    vec2 d = dir.xy;
    vec2 s = f.sun.xy;
    float cos_phi = 1.0;
    if (dot(d, d) > 1e-12 && dot(s, s) > 1e-12) {
        cos_phi = dot(d, s) * inversesqrt(dot(d, d) * dot(s, s));
    }
    float phi = acos(clamp(cos_phi, -1.0, 1.0));
    float theta = acos(clamp(dir.z, -1.0, 1.0));
    vec2 unit = atmosphere_sky_view_unit(a, r, phi, theta);
    uint handle = f.atmosphere.z;
    vec2 size = vec2(textureSize(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), 0));
    vec2 uv = vec2(atmosphere_unit_to_uv(unit.x, size.x), atmosphere_unit_to_uv(unit.y, size.y));
    vec3 radiance = textureLod(sampler2D(g_textures[handle], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0).rgb;
    return max(radiance, vec3(0.0));
}

#endif
