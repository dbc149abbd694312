// Shading of splat surfaces (§10.2.3 pass 3 and the opaque modes) under the
// frame's lighting, exactly as the terrain (glsl/include/surface_lighting.glsl:
// sun with shadows, sky light, aerial perspective), from camera-space normal
// and position.
#ifndef ALPENGLOW_SPLAT_SHADING_GLSL
#define ALPENGLOW_SPLAT_SHADING_GLSL

#include "splat.glsl"
#include "surface_lighting.glsl"

vec3 camera_to_world(vec3 v) {
    uint f = pc.handles.y;
    return vec3(dot(g_point_frame[f].camera_to_world[0].xyz, v), dot(g_point_frame[f].camera_to_world[1].xyz, v),
                dot(g_point_frame[f].camera_to_world[2].xyz, v));
}

// The world normal AOV of a camera-space normal at camera-space `position`,
// turned towards the viewer as shade_splat turns it; w = 1.
vec4 world_normal(vec3 normal, vec3 position) {
    vec3 n = normalize(normal);
    return vec4(camera_to_world(dot(n, position) > 0.0 ? -n : n), 1.0);
}

// Radiance of albedo `albedo` at camera-space `position` with normal `normal`
// (two-sided: the normal is turned towards the viewer), and the lighting
// AOVs in `visibility`. Unlit (albedo out, visibility 1) when the frame's
// lighting.y is 0.
vec3 shade_splat(vec3 albedo, vec3 normal, vec3 position, out vec2 visibility) {
    uint f = pc.handles.y;
    uvec4 lighting = g_point_frame[f].lighting;
    if (lighting.y == 0u) {
        visibility = vec2(1.0);
        return albedo;
    }
    vec3 n = normalize(normal);
    if (dot(n, position) > 0.0) {
        n = -n;
    }
    vec3 eye = g_point_frame[f].eye.xyz;
    vec3 world = eye + camera_to_world(position);
    return shade_diffuse(lighting.x, albedo, world, camera_to_world(n), -position.z, eye, true, visibility);
}

#endif
