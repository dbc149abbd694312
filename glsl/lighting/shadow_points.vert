#version 460
// points.shadow, vertex stage (§9.5, §10.1.6): each splat of an instance's
// prefix that passes the interval test r_min ≤ r < r_max (r: its distance
// from the view's eye in object units, as in glsl/points/splat.vert) becomes
// a quad in its tangent plane, of its disc radius, in world space, drawn
// into one cascade of the shadow atlas; six vertices per splat (vertex
// pulling). Records: src/points/render/shadow.rs.
#include "../include/heap.glsl"

// As in glsl/include/splat.glsl (which declares the points passes' own push constants).
struct Splat {
    vec4 position_rmin;  // object-space centre, r_min
    vec4 normal_rmax;    // object-space unit normal, r_max
    vec4 radius_color;   // disk radius (object units), colour bits, 0, 0
    vec4 clip;           // clip lines (unused by the caster)
};
layout(set = 0, binding = 2, std430) readonly buffer Splats { Splat s[]; } g_splats[];

// Orthonormal tangent frame of a unit normal (Duff et al. 2017), as in splat.glsl.
void tangent_frame(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float bb = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * bb, -s * n.x);
    b = vec3(bb, s + n.y * n.y * a, -n.y);
}

struct ShadowInstance {
    mat4 model;    // object → world (rigid motion × uniform scale)
    vec4 params;   // scale, first splat (bits), prefix length (bits), 0
};

layout(set = 0, binding = 2, std430) readonly buffer ShadowPoints {
    vec4 eye;      // world eye position of the view
    ShadowInstance instances[];
} g_shadow_points[];

layout(push_constant) uniform ShadowPush {
    mat4 view_proj;   // world → atlas clip space of the cascade
    vec4 sun_texel;   // xyz: towards the sun, w: texel size (m)
    uvec4 handles;    // splats, shadow records, instance record, 0
} sp;

layout(location = 0) out vec2 out_uv;

const vec2 CORNERS[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
    uint splat_index = uint(gl_VertexIndex) / 6u;
    vec2 uv = CORNERS[uint(gl_VertexIndex) % 6u];
    ShadowInstance inst = g_shadow_points[sp.handles.y].instances[sp.handles.z];
    float scale = inst.params.x;
    uint first = floatBitsToUint(inst.params.y);
    Splat s = g_splats[sp.handles.x].s[first + splat_index];
    vec3 centre = (inst.model * vec4(s.position_rmin.xyz, 1.0)).xyz;
    float r = length(centre - g_shadow_points[sp.handles.y].eye.xyz) / scale;
    out_uv = uv;
    if (!(s.position_rmin.w <= r && r < s.normal_rmax.w)) {
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // outside the depth range: clipped
        return;
    }
    vec3 n = normalize(mat3(inst.model) * s.normal_rmax.xyz);
    vec3 t, b;
    tangent_frame(n, t, b);
    vec3 sun = sp.sun_texel.xyz;
    float texel = sp.sun_texel.w;
    float c = clamp(abs(dot(n, sun)), 1e-3, 1.0);
    float tan_theta = min(sqrt(1.0 - c * c) / c, 4.0);
    vec3 p = centre + (t * uv.x + b * uv.y) * (s.radius_color.x * scale);
    p -= sun * texel * (0.5 + 0.5 * tan_theta);
    gl_Position = sp.view_proj * vec4(p, 1.0);
}
