#version 460
// terrain.raster (the compute path's rasterizer of the warped grid, §7.4.2;
// issue 28): one thread a grid triangle. A triangle wholly behind the near
// plane, beyond the far plane or off the image is culled; one that crosses
// the near plane, lies far off the image or spans more than BIG_PIXELS of
// bounding box goes to terrain.raster_big's list; the rest are rasterized
// here: fixed-point edge functions with a tie rule at the pixel centres
// (watertight: no pixel of a shared edge is covered twice or missed), a
// perspective-correct view depth, and an atomicMin of (depth, id) into the
// visibility buffer.
#include "../include/terrain_visibility.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // view constants, grid vertices, visibility buffer, big-triangle list
} pc;

// Bounding boxes larger than this go to terrain.raster_big.
const uint BIG_PIXELS = 64u;

void raster_triangle(ComputeView view, uint t) {
    uvec3 i = grid_triangle(t, view.size.z);
    vec4 c[3] = vec4[3](grid_clip(view, pc.handles.y, i.x), grid_clip(view, pc.handles.y, i.y),
                        grid_clip(view, pc.handles.y, i.z));
    float near = view.clip.x, far = view.clip.y;
    // Frustum culling against the side planes, the near and the far plane.
    for (int axis = 0; axis < 2; ++axis) {
        if (c[0][axis] > c[0].w && c[1][axis] > c[1].w && c[2][axis] > c[2].w) return;
        if (c[0][axis] < -c[0].w && c[1][axis] < -c[1].w && c[2][axis] < -c[2].w) return;
    }
    if (max(c[0].w, max(c[1].w, c[2].w)) < near || min(c[0].w, min(c[1].w, c[2].w)) > far) {
        return;
    }
    vec2 size = vec2(view.size.xy);
    bool big = min(c[0].w, min(c[1].w, c[2].w)) < near;
    vec2 lo = vec2(0.0), hi = vec2(0.0);
    if (!big) {
        vec2 s0 = screen_position(c[0], size), s1 = screen_position(c[1], size), s2 = screen_position(c[2], size);
        lo = min(s0, min(s1, s2));
        hi = max(s0, max(s1, s2));
        big = any(lessThan(lo, vec2(-FIXED_LIMIT))) || any(greaterThan(hi, size + FIXED_LIMIT));
    }
    if (big) {
        uint slot = atomicAdd(g_big_triangles[pc.handles.w].count, 1u);
        g_big_triangles[pc.handles.w].ids[slot] = t;
        return;
    }
    FixedTriangle tri;
    if (!setup_fixed(c, size, tri)) {
        return;
    }
    ivec2 first, last;
    fixed_bounds(tri, ivec2(view.size.xy), first, last);
    if (any(lessThan(last, first))) {
        return;
    }
    if (uint(last.x - first.x + 1) * uint(last.y - first.y + 1) > BIG_PIXELS) {
        uint slot = atomicAdd(g_big_triangles[pc.handles.w].count, 1u);
        g_big_triangles[pc.handles.w].ids[slot] = t;
        return;
    }
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            float depth = fixed_coverage(tri, ivec2(x, y));
            if (depth >= near && depth <= far) {
                store_hit(pc.handles.z, uint(y) * view.size.x + uint(x), depth, t);
            }
        }
    }
}

// A grid-stride loop: the dispatch stays within maxComputeWorkGroupCount
// (65535 workgroups) at any grid size.
void main() {
    ComputeView view = g_compute_views[pc.handles.x].v;
    for (uint t = gl_GlobalInvocationID.x; t < view.size.w; t += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        raster_triangle(view, t);
    }
}
