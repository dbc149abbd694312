#version 460
// points.shadow on the compute path (§9.5, §10.1.6; issues 28–29): the
// point casters rasterized by compute into the atlas's buffer of depth bits
// that the terrain's compute casters write (atomicMin: the caster nearest
// the sun), before shadow.copy. One dispatch a cascade over every splat of
// the view's caster draws (a draw table: each draw's first splat counted
// over the draws, and its record). A splat's disc (glsl/include/shadow_points.glsl)
// projects orthographically to an ellipse: the texel centres of its box
// within the cascade's receivers' texels are mapped back to the disc's
// (u, v) by the inverse of the projection's 2×2 part, kept inside u² + v² ≤ 1
// (the hardware pass's discard), and take the disc's depth there (linear).
#include "../include/shadow_points.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 2, std430) buffer ShadowDepths { uint d[]; } g_shadow_depths[];
layout(set = 0, binding = 2, std430) readonly buffer ShadowDraws { uvec2 d[]; } g_shadow_draws[];

// src/points/render/shadow.rs, ComputeCasterPush.
layout(push_constant) uniform Push {
    mat4 view_proj;   // world → atlas clip space of the cascade (orthographic)
    vec4 sun_texel;   // xyz: towards the sun, w: texel size (m)
    uvec4 handles;    // splats, shadow records, depth bits, draw table
    uvec4 counts;     // draws, splats, atlas side, 0
    uvec4 receivers;  // the texels the cascade's receivers sample: first x, y, last x, y
} pc;

// The draw of splat `index` of the view's casters: its record and the
// splat's index in the draw.
uvec2 find_draw(uint index) {
    uint lo = 0u, hi = pc.counts.x;  // the last draw whose first splat ≤ index
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (g_shadow_draws[pc.handles.w].d[mid].x <= index) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    uvec2 draw = g_shadow_draws[pc.handles.w].d[lo];
    return uvec2(draw.y, index - draw.x);
}

void cast_splat(uint index) {
    uvec2 draw = find_draw(index);
    CasterDisc d;
    if (!caster_disc(pc.handles.xy, draw.x, draw.y, pc.sun_texel, d)) {
        return;
    }
    float size = float(pc.counts.z);
    vec4 c = pc.view_proj * vec4(d.centre, 1.0);
    vec3 du = (pc.view_proj * vec4(d.u, 0.0)).xyz;
    vec3 dv = (pc.view_proj * vec4(d.v, 0.0)).xyz;
    // Texel position = s0 + u·su + v·sv (atlas clip → texels, as terrain_visibility.glsl's screen_position).
    vec2 s0 = (c.xy * 0.5 + 0.5) * size;
    vec2 su = du.xy * 0.5 * size, sv = dv.xy * 0.5 * size;
    float det = su.x * sv.y - su.y * sv.x;
    if (abs(det) < 1e-12) {
        return;  // edge-on to the sun: no area
    }
    vec2 extent = abs(su) + abs(sv);
    ivec2 first = max(ivec2(ceil(s0 - extent - 0.5)), ivec2(pc.receivers.xy));
    ivec2 last = min(ivec2(floor(s0 + extent - 0.5)), ivec2(pc.receivers.zw));
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            vec2 p = vec2(x, y) + 0.5 - s0;
            vec2 uv = vec2(p.x * sv.y - p.y * sv.x, su.x * p.y - su.y * p.x) / det;
            float depth = c.z + uv.x * du.z + uv.y * dv.z;
            // Depths outside [0, 1] are clipped, as the hardware clips them.
            if (dot(uv, uv) <= 1.0 && depth >= 0.0 && depth <= 1.0) {
                uint bits = depth > 0.0 ? floatBitsToUint(depth) : 0u;
                atomicMin(g_shadow_depths[pc.handles.z].d[uint(y) * pc.counts.z + uint(x)], bits);
            }
        }
    }
}

// A grid-stride loop: the dispatch stays within maxComputeWorkGroupCount.
void main() {
    for (uint i = gl_GlobalInvocationID.x; i < pc.counts.y; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        cast_splat(i);
    }
}
