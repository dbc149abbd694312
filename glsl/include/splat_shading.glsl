// Shading of splat surfaces: sun, sky ambient and haze as on the terrain
// (glsl/terrain/draw.frag), from camera-space normal and position.
#ifndef ALPENGLOW_SPLAT_SHADING_GLSL
#define ALPENGLOW_SPLAT_SHADING_GLSL

#include "atmosphere.glsl"
#include "splat.glsl"

vec3 camera_to_world(vec3 v) {
    uint f = pc.handles.y;
    return vec3(dot(g_point_frame[f].camera_to_world[0].xyz, v), dot(g_point_frame[f].camera_to_world[1].xyz, v),
                dot(g_point_frame[f].camera_to_world[2].xyz, v));
}

// Radiance of albedo `albedo` at camera-space `position` with normal `normal`
// (two-sided: the normal is turned towards the viewer). Unlit (albedo out)
// when the frame's sun_camera.w is 0.
vec3 shade_splat(vec3 albedo, vec3 normal, vec3 position) {
    uint f = pc.handles.y;
    if (g_point_frame[f].sun_camera.w == 0.0) {
        return albedo;
    }
    vec3 n = normalize(normal);
    if (dot(n, position) > 0.0) {
        n = -n;
    }
    vec3 nw = camera_to_world(n);
    vec3 sun = normalize(camera_to_world(g_point_frame[f].sun_camera.xyz));
    float dist = length(position);
    vec3 dir = camera_to_world(position / max(dist, 1e-6));
    vec3 sky_ambient = mix(SKY_HORIZON, SKY_ZENITH, 0.5 + 0.5 * nw.z) * (0.5 + 0.5 * nw.z);
    vec3 radiance = albedo * (SUN_RADIANCE * max(dot(nw, sun), 0.0) + sky_ambient);
    return apply_haze(radiance, dist, dir, sun);
}

#endif
