// The point objects as shadow casters (§9.5, §10.1.6; src/points/render/shadow.rs):
// the records of points.shadow and each splat's disc in world space, shared
// by the hardware pass (glsl/lighting/shadow_points.vert) and the compute
// path's (glsl/lighting/shadow_points.comp).
#ifndef ALPENGLOW_SHADOW_POINTS_GLSL
#define ALPENGLOW_SHADOW_POINTS_GLSL

#include "heap.glsl"
#include "tangent_frame.glsl"

// As in glsl/include/splat.glsl (which declares the points passes' own push constants).
struct Splat {
    vec4 position_rmin;  // object-space centre, r_min
    vec4 normal_rmax;    // object-space unit normal, r_max
    vec4 radius_color;   // disk radius (object units), colour bits, view-dependent error bits, parent (glsl/include/spt_interval.glsl)
    vec4 clip;           // clip lines (unused by the caster)
};
layout(set = 0, binding = 2, std430) readonly buffer Splats { Splat s[]; } g_splats[];
#include "spt_interval.glsl"


struct ShadowInstance {
    mat4 model;    // object → world (rigid motion × uniform scale)
    vec4 params;   // scale, first splat (bits), prefix length (bits), 0
};

layout(set = 0, binding = 2, std430) readonly buffer ShadowPoints {
    vec4 eye;      // world eye position of the view; w: the interval test (uint bits, SPT_ERROR_*)
    ShadowInstance instances[];
} g_shadow_points[];

// A caster disc in world space: centre (pushed away from the sun by the
// slope-scaled bias), tangent axes scaled to its radius.
struct CasterDisc {
    vec3 centre;
    vec3 u;
    vec3 v;
};

// Splat `splat_index` of record `record` (in splats `splats`, records
// `records`) as a caster disc for the sun `sun` and texel size `texel`;
// false when it fails the interval test r_min ≤ r < r_max (r: its distance
// from the view's eye in object units, as in glsl/points/splat.vert).
bool caster_disc(uvec2 buffers, uint record, uint splat_index, vec4 sun_texel, out CasterDisc d) {
    ShadowInstance inst = g_shadow_points[buffers.y].instances[record];
    float scale = inst.params.x;
    uint first = floatBitsToUint(inst.params.y);
    Splat s = g_splats[buffers.x].s[first + splat_index];
    vec3 centre = (inst.model * vec4(s.position_rmin.xyz, 1.0)).xyz;
    vec4 eye = g_shadow_points[buffers.y].eye;
    float r = length(centre - eye.xyz) / scale;
    if (!spt_interval(buffers.x, first + splat_index, r, floatBitsToUint(eye.w), inst.model, eye.xyz)) {
        return false;
    }
    vec3 n = normalize(mat3(inst.model) * s.normal_rmax.xyz);
    vec3 t, b;
    tangent_frame(n, t, b);
    vec3 sun = sun_texel.xyz;
    float c = clamp(abs(dot(n, sun)), 1e-3, 1.0);
    float tan_theta = min(sqrt(1.0 - c * c) / c, 4.0);
    float radius = s.radius_color.x * scale;
    d.centre = centre - sun * sun_texel.w * (0.5 + 0.5 * tan_theta);
    d.u = t * radius;
    d.v = b * radius;
    return true;
}

#endif
