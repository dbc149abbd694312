// The terrain's compute path (issue 28; the geometry is §7.4.2's warped
// grid, src/terrain/visibility.rs): what terrain.raster, terrain.raster_big
// and terrain.shade share. The visibility buffer holds one 64-bit key per
// pixel: the view depth's float bits in the high word (positive floats
// order as unsigned integers, so atomicMin keeps the nearest), the grid
// triangle's id in the low word; ~0 where no triangle covers the pixel.
#ifndef ALPENGLOW_TERRAIN_VISIBILITY_GLSL
#define ALPENGLOW_TERRAIN_VISIBILITY_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "heap.glsl"

// One view's constants (src/terrain/visibility.rs, ComputeView).
struct ComputeView {
    mat4 view_proj_rel;  // eye-relative world → clip (projection × view rotation)
    vec4 eye;            // xyz, w = d0 (as terrain.draw)
    vec4 forward;        // xyz: camera forward axis; w = pixel footprint per metre of depth
    vec4 ray_right;      // the view ray through NDC (x, y) is ray_forward + x·ray_right − y·ray_up
    vec4 ray_up;
    vec4 ray_forward;
    uvec4 size;          // width, height, grid side, triangles
    vec4 clip;           // near, far, detail amplitude, detail H
};

layout(set = 0, binding = 2, std430) readonly buffer ComputeViews { ComputeView v; } g_compute_views[];
layout(set = 0, binding = 2, std430) readonly buffer GridVertices { vec4 v[]; } g_grid_vertices[];
layout(set = 0, binding = 2, std430) buffer VisibilityKeys { uint64_t k[]; } g_visibility[];
// Triangles terrain.raster leaves to terrain.raster_big: count, then ids.
layout(set = 0, binding = 2, std430) buffer BigTriangles { uint count; uint pad[3]; uint ids[]; } g_big_triangles[];

const uint64_t NO_HIT = ~uint64_t(0);

// The grid vertex indices of triangle `t` of a `side`² grid, as
// src/terrain/geometry_image.rs `grid_indices` orders them.
uvec3 grid_triangle(uint t, uint side) {
    uint quad = t >> 1u;
    uint i = (quad / (side - 1u)) * side + quad % (side - 1u);
    return (t & 1u) == 0u ? uvec3(i, i + 1u, i + side) : uvec3(i + 1u, i + side + 1u, i + side);
}

// Vertex `i` of the geometry image: xyz world, w split octave.
vec4 grid_position(uint vertices, uint i) {
    return g_grid_vertices[vertices].v[2u * i];
}

// Vertex `i`'s normal: xyz, w debug scalar.
vec4 grid_normal(uint vertices, uint i) {
    return g_grid_vertices[vertices].v[2u * i + 1u];
}

// Clip coordinates of vertex `i` (eye-relative, so large worlds keep precision).
// `precise`: a vertex shared by several triangles must land on the same
// fixed-point position in each (no contraction that differs by call site).
vec4 grid_clip(ComputeView view, uint vertices, uint i) {
    precise vec3 rel = grid_position(vertices, i).xyz - view.eye.xyz;
    precise vec4 clip = view.view_proj_rel * vec4(rel, 1.0);
    return clip;
}

// Fixed-point screen position (SUBPIXEL_BITS below the pixel) of a clip
// position in front of the camera; the pixel grid's y grows downwards
// (Vulkan's viewport).
const int SUBPIXEL_BITS = 8;
const float SUBPIXELS = 256.0;
// Beyond this many pixels off the image a triangle takes the float path.
const float FIXED_LIMIT = 1048576.0;

vec2 screen_position(vec4 clip, vec2 size) {
    precise vec2 screen = (clip.xy / clip.w * 0.5 + 0.5) * size;
    return screen;
}

i64vec2 fixed_point(vec2 screen) {
    return i64vec2(round(screen * SUBPIXELS));
}

// Edge function of edge a→b at p: positive inside a positively wound triangle.
int64_t edge_function(i64vec2 a, i64vec2 b, i64vec2 p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// The tie rule: a pixel centre exactly on edge a→b belongs to the triangle
// only for one of the edge's two directions, so two triangles sharing the
// edge never both cover it nor both miss it.
int64_t edge_bias(i64vec2 a, i64vec2 b) {
    i64vec2 d = b - a;
    return (d.y < 0 || (d.y == 0 && d.x > 0)) ? int64_t(0) : int64_t(-1);
}

// A triangle set up in fixed point: vertices (wound positively), biases,
// twice its area, the clip w of each vertex; `flipped`: the second and third
// vertex were swapped for the winding.
struct FixedTriangle {
    i64vec2 v[3];
    int64_t bias[3];
    int64_t area;
    vec3 inv_w;
    bool flipped;
};

// Sets up the triangle of clip positions `c`; false when it has no area.
bool setup_fixed(vec4 c[3], vec2 size, out FixedTriangle tri) {
    i64vec2 a = fixed_point(screen_position(c[0], size));
    i64vec2 b = fixed_point(screen_position(c[1], size));
    i64vec2 d = fixed_point(screen_position(c[2], size));
    int64_t area = edge_function(a, b, d);
    tri.inv_w = vec3(1.0 / c[0].w, 1.0 / c[1].w, 1.0 / c[2].w);
    tri.flipped = area < 0;
    if (area == 0) {
        return false;
    }
    if (area < 0) {
        i64vec2 t = b;
        b = d;
        d = t;
        area = -area;
        tri.inv_w = tri.inv_w.xzy;
    }
    tri.v[0] = a;
    tri.v[1] = b;
    tri.v[2] = d;
    tri.bias[0] = edge_bias(b, d);
    tri.bias[1] = edge_bias(d, a);
    tri.bias[2] = edge_bias(a, b);
    tri.area = area;
    return true;
}

// The pixels whose centres may lie in `tri`, clamped to the `size` image:
// from the fixed-point vertices themselves (the float positions round by
// up to half a sub-pixel, and a box from them could drop an edge's pixel).
void fixed_bounds(FixedTriangle tri, ivec2 size, out ivec2 first, out ivec2 last) {
    i64vec2 lo = min(tri.v[0], min(tri.v[1], tri.v[2])) - int64_t(SUBPIXELS / 2.0);
    i64vec2 hi = max(tri.v[0], max(tri.v[1], tri.v[2])) - int64_t(SUBPIXELS / 2.0);
    // ceil(lo / 256) and floor(hi / 256) by arithmetic shifts.
    first = max(ivec2(-((-lo) >> SUBPIXEL_BITS)), ivec2(0));
    last = min(ivec2(hi >> SUBPIXEL_BITS), size - 1);
}

// Whether the triangle covers the centre of pixel `pixel`, and there its
// screen-space barycentrics (of the wound vertices `tri.v`).
bool fixed_barycentrics(FixedTriangle tri, ivec2 pixel, out vec3 lambda) {
    i64vec2 p = i64vec2(pixel) * int64_t(SUBPIXELS) + int64_t(SUBPIXELS / 2.0);
    int64_t e0 = edge_function(tri.v[1], tri.v[2], p);
    int64_t e1 = edge_function(tri.v[2], tri.v[0], p);
    int64_t e2 = edge_function(tri.v[0], tri.v[1], p);
    lambda = vec3(float(e0), float(e1), float(e2)) / float(tri.area);
    return e0 + tri.bias[0] >= 0 && e1 + tri.bias[1] >= 0 && e2 + tri.bias[2] >= 0;
}

// The view depth of the triangle at pixel `pixel` if it covers the pixel's
// centre, else a negative value.
float fixed_coverage(FixedTriangle tri, ivec2 pixel) {
    vec3 lambda;
    if (!fixed_barycentrics(tri, pixel, lambda)) {
        return -1.0;
    }
    // Perspective-correct: 1/w is linear in screen space.
    return 1.0 / dot(lambda, tri.inv_w);
}

// Keeps the nearer of what the pixel holds and triangle `t` at `depth`.
void store_hit(uint visibility, uint pixel, float depth, uint t) {
    uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(t);
    atomicMin(g_visibility[visibility].k[pixel], key);
}

#endif
