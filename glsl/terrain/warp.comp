#version 460
// terrain.warp: warp and zoom of geometry image warping (dissertation §7.4.2
// "Warp and Zoom", §7.4.3 "Procedural Detail"; ALGORITHMS.md §3 items 5–7).
//
// Every output vertex (i, j) of the N×N grid:
//  1. Φ: the CPU's warped sketch map (n×n world xy) bilinearly interpolated
//     at (i, j)·(n−1)/(N−1), clamped onto the terrain's rectangle;
//  2. height re-sampled from the sketch atlas there with the cubic B-spline
//     (src/surface/bspline.rs uses the same taps and clamping);
//  3. split octave o = log2(d0 / d) − SPLIT_BIAS, d the largest 3D distance
//     to the four grid neighbours (from Φ and the atlas gradient);
//  4. procedural displacement: wavelet octaves up to o (terrain_detail.glsl);
//  5. normal of the surface itself: the B-spline's analytic gradient plus
//     the detail octaves' (not central differences of the grid: per-line
//     warps shear the grid, so a vertex's row neighbours can lie hundreds
//     of metres apart in x and a difference stencil across them misreads
//     rough ground, seen as rows of bright and dark specks from above).
// Written straight into the vertex buffer that terrain.draw draws
// (render-to-vertex-buffer): position (xyz, w = split octave) and normal
// (xyz, w = debug scalar carried from the CPU).
//
// A workgroup computes its 8×8 vertices plus a one-vertex halo (10×10) in
// shared memory: the split octave needs the neighbours' positions.
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/bspline_height.glsl"
#include "../include/detail_window.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

struct Vertex {
    vec4 position;
    vec4 normal;
};

layout(set = 0, binding = 2, std430) writeonly buffer Vertices { Vertex v[]; } g_vertices[];
layout(set = 0, binding = 2, std430) readonly buffer Warp { vec4 t[]; } g_warp[];

layout(push_constant) uniform Push {
    uvec4 handles;   // atlas heights (sampled), warp (storage), vertices (storage), noise tile (sampled)
    uvec4 grid;      // output side N, sketch side n, atlas columns, atlas rows
    vec4 spacing;    // atlas dx, dy, detail amplitude (× d0), detail H
    vec4 extent;     // terrain x max, y max, d0, detail on (1) / off (0)
    DetailWindow window;  // the streamed detail window (detail_window.glsl)
} pc;

shared vec4 s_position[10][10];  // xyz, w = split octave
shared float s_debug[10][10];
shared vec3 s_normal[10][10];

// Φ at output vertex g (bilinear in the sketch grid) and the debug scalar.
vec3 phi(ivec2 g) {
    uint n = pc.grid.y;
    vec2 s = vec2(g) * float(n - 1u) / float(pc.grid.x - 1u);
    uvec2 c = min(uvec2(s), uvec2(n - 2u));
    vec2 f = s - vec2(c);
    uint h = pc.handles.y;
    vec4 a = g_warp[h].t[c.y * n + c.x];
    vec4 b = g_warp[h].t[c.y * n + c.x + 1u];
    vec4 d = g_warp[h].t[(c.y + 1u) * n + c.x];
    vec4 e = g_warp[h].t[(c.y + 1u) * n + c.x + 1u];
    vec3 v = mix(mix(a.xyz, b.xyz, f.x), mix(d.xyz, e.xyz, f.x), f.y);
    v.xy = clamp(v.xy, vec2(0.0), pc.extent.xy);
    return v;
}

void main() {
    int side = int(pc.grid.x);
    ivec2 group = ivec2(gl_WorkGroupID.xy) * 8 - 1;
    float d0 = pc.extent.z;
    for (uint k = gl_LocalInvocationIndex; k < 100u; k += 64u) {
        ivec2 local = ivec2(k % 10u, k / 10u);
        ivec2 g = clamp(group + local, ivec2(0), ivec2(side - 1));
        vec3 p = phi(g);
        vec2 grad;
        float window;
        float h = detail_surface(pc.window, pc.handles.x, pc.grid.zw, pc.spacing.xy, p.xy, grad, window);
        // Where the window's samples are drawn they replace the procedural
        // octaves coarser than their spacing (the ones between d0 and it):
        // geometry adds octaves from o_window, shading from the split up.
        float o_window = detail_window_octave(pc.window, window, d0);
        // Largest distance to the four grid neighbours, heights from the
        // atlas gradient.
        float d2 = 0.0;
        ivec2 offsets[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
        for (int o = 0; o < 4; ++o) {
            ivec2 q = clamp(g + offsets[o], ivec2(0), ivec2(side - 1));
            vec2 dxy = phi(q).xy - p.xy;
            float dz = dot(grad, dxy);
            d2 = max(d2, dot(dxy, dxy) + dz * dz);
        }
        float split = clamp(log2(d0 / max(sqrt(d2), 1e-6)) - SPLIT_BIAS, 0.0, float(MAX_DETAIL_OCTAVES));
        split = max(split, min(o_window, float(MAX_DETAIL_OCTAVES)));
        if (pc.extent.w > 0.5) {
            vec2 dgrad;
            h += detail_octaves(pc.handles.w, p.xy, d0, pc.spacing.z, pc.spacing.w, o_window, split, dgrad);
            grad += dgrad;
        }
        s_position[local.y][local.x] = vec4(p.xy, h, split);
        s_normal[local.y][local.x] = normalize(vec3(-grad, 1.0));
        s_debug[local.y][local.x] = p.z;
    }
    barrier();

    ivec2 id = ivec2(gl_GlobalInvocationID.xy);
    if (id.x >= side || id.y >= side) {
        return;
    }
    ivec2 l = ivec2(gl_LocalInvocationID.xy) + 1;
    vec3 n = s_normal[l.y][l.x];
    vec4 p = s_position[l.y][l.x];
    uint index = uint(id.y * side + id.x);
    g_vertices[pc.handles.z].v[index].position = p;
    g_vertices[pc.handles.z].v[index].normal = vec4(n, s_debug[l.y][l.x]);
}
