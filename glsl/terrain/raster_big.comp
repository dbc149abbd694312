#version 460
// terrain.raster_big (issue 28): the triangles terrain.raster left over —
// more than a few pixels of bounding box, crossing the near plane or far
// off the image — one workgroup a triangle (the workgroups loop over the
// list), its threads striding over the bounding box's pixels. In front of
// the near plane the test is terrain.raster's fixed-point one; a triangle
// crossing it is tested in 2D homogeneous coordinates (Olano and Greer
// 1997: no clipping, the bounding box from the triangle clipped to the
// near plane), where an edge may be taken by both neighbours (atomicMin
// keeps one) but never missed.
#include "../include/terrain_visibility.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // view constants, grid vertices, visibility buffer, big-triangle list
} pc;

// The screen bounding box of triangle `c` clipped to w ≥ near: lo, hi.
void clipped_bounds(vec4 c[3], float near, vec2 size, out vec2 lo, out vec2 hi) {
    lo = vec2(1e30);
    hi = vec2(-1e30);
    for (int k = 0; k < 3; ++k) {
        vec4 a = c[k], b = c[(k + 1) % 3];
        if (a.w >= near) {
            vec2 s = screen_position(a, size);
            lo = min(lo, s);
            hi = max(hi, s);
        }
        if ((a.w - near) * (b.w - near) < 0.0) {
            vec4 m = mix(a, b, (near - a.w) / (b.w - a.w));
            m.w = near;
            vec2 s = screen_position(m, size);
            lo = min(lo, s);
            hi = max(hi, s);
        }
    }
}

// The view depth of the triangle `c` at `pixel` in homogeneous coordinates,
// or a negative value off the triangle or behind the eye.
float homogeneous_coverage(vec4 c[3], ivec2 pixel, vec2 size) {
    vec3 v0 = c[0].xyw, v1 = c[1].xyw, v2 = c[2].xyw;
    vec3 r0 = cross(v1, v2), r1 = cross(v2, v0), r2 = cross(v0, v1);
    float det = dot(v0, r0);
    if (det == 0.0) {
        return -1.0;
    }
    vec3 p = vec3((vec2(pixel) + 0.5) / size * 2.0 - 1.0, 1.0);
    vec3 q = vec3(dot(r0, p), dot(r1, p), dot(r2, p)) / det;
    float s = q.x + q.y + q.z;
    if (s <= 0.0 || any(lessThan(q, vec3(0.0)))) {
        return -1.0;
    }
    return 1.0 / s;
}

void main() {
    ComputeView view = g_compute_views[pc.handles.x].v;
    uint count = g_big_triangles[pc.handles.w].count;
    vec2 size = vec2(view.size.xy);
    float near = view.clip.x, far = view.clip.y;
    for (uint b = gl_WorkGroupID.x; b < count; b += gl_NumWorkGroups.x) {
        uint t = g_big_triangles[pc.handles.w].ids[b];
        uvec3 i = grid_triangle(t, view.size.z);
        vec4 c[3] = vec4[3](grid_clip(view, pc.handles.y, i.x), grid_clip(view, pc.handles.y, i.y),
                            grid_clip(view, pc.handles.y, i.z));
        vec2 lo, hi;
        clipped_bounds(c, near, size, lo, hi);
        bool fixed_path = min(c[0].w, min(c[1].w, c[2].w)) >= near &&
                          all(greaterThanEqual(lo, vec2(-FIXED_LIMIT))) && all(lessThanEqual(hi, size + FIXED_LIMIT));
        FixedTriangle tri;
        if (fixed_path && !setup_fixed(c, size, tri)) {
            continue;
        }
        ivec2 first = max(ivec2(ceil(clamp(lo, vec2(-1.0), size) - 0.5)), ivec2(0));
        ivec2 last = min(ivec2(floor(clamp(hi, vec2(-1.0), size) - 0.5)), ivec2(view.size.xy) - 1);
        if (fixed_path) {
            fixed_bounds(tri, ivec2(view.size.xy), first, last);
        }
        if (any(lessThan(last, first))) {
            continue;
        }
        uint columns = uint(last.x - first.x + 1);
        uint pixels = columns * uint(last.y - first.y + 1);
        for (uint k = gl_LocalInvocationID.x; k < pixels; k += gl_WorkGroupSize.x) {
            ivec2 pixel = first + ivec2(k % columns, k / columns);
            float depth = fixed_path ? fixed_coverage(tri, pixel) : homogeneous_coverage(c, pixel, size);
            if (depth >= near && depth <= far) {
                store_hit(pc.handles.z, uint(pixel.y) * view.size.x + uint(pixel.x), depth, t);
            }
        }
    }
}
