// Shading of a diffuse surface point under the frame's lighting (§9;
// ALGORITHMS.md §6): direct sun × sun visibility (shadows.glsl) + sky light
// (sky_light.glsl), then aerial perspective towards the eye. Used by
// terrain.draw and the points passes alike.
#ifndef ALPENGLOW_SURFACE_LIGHTING_GLSL
#define ALPENGLOW_SURFACE_LIGHTING_GLSL

#include "lighting.glsl"
#include "sky.glsl"
#include "aerial_perspective.glsl"
#include "shadows.glsl"
#include "sky_light.glsl"

const float PI = 3.14159265358979;

// The albedo a surface of texture albedo `albedo` is lit with.
vec3 lit_albedo(uint lighting, vec3 albedo) {
    LightingFrame l = g_lighting[lighting].f;
    return (l.models.w & LIGHTING_ALBEDO_OVERRIDE) != 0u ? vec3(l.exposure.w) : albedo;
}

// Radiance leaving a Lambertian point of albedo `albedo` at `world` (normal
// `normal`, `view_depth` metres ahead of the camera at `eye`) towards the
// eye, aerial perspective included. `visibility`: (sun visibility, sky
// visibility), the AOVs. `point_object`: a point object's surface
// (sky_light.glsl).
vec3 shade_diffuse(uint lighting, vec3 albedo, vec3 world, vec3 normal, float view_depth, vec3 eye,
                   bool point_object, out vec2 visibility) {
    vec3 a = lit_albedo(lighting, albedo);
    vec3 sun = g_lighting[lighting].f.sun.xyz;
    uint flags = g_lighting[lighting].f.models.w;
    float sun_vis = sun_visibility(lighting, world, normal, view_depth);
    vec4 sky = sky_light(lighting, world, normal, point_object);
    vec3 radiance = a * sky.rgb;
    if ((flags & LIGHTING_NO_SUN_DIRECT) == 0u) {
        radiance += a / PI * g_lighting[lighting].f.sun_irradiance.rgb * max(dot(normal, sun), 0.0) * sun_vis;
    }
    visibility = vec2(sun_vis, sky.a);
    if ((flags & LIGHTING_NO_AERIAL_PERSPECTIVE) != 0u) {
        return radiance;
    }
    return aerial_perspective(lighting, radiance, eye, world);
}

#endif
