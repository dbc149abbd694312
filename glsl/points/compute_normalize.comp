#version 460
// points.normalize on the compute path (dissertation §10.2.3, Table 10.1
// pass 3): per pixel the fixed-point sums of points.accumulate
// (glsl/include/splat_compute_state.glsl) divided and shaded as the
// hardware path's points.normalize (glsl/include/splat_resolve.glsl). Σw = 0
// (no splat) keeps what the terrain and sky (or the hybrid triangles)
// wrote, and W is 0 there unless the triangles wrote it. The ids are those
// of the splat that won the visibility pass, or where none did (its
// pushed-back depth lost against the terrain's, the surface is in front of
// it) of the last splat accumulated.
#define SPLAT_RESOLVE_COMPUTE
#include "../include/splat_compute_state.glsl"
#include "../include/splat_resolve.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (sums, point frame, 1: keep W where no splat, nearest words),
//   mode.x = last records, outputs, more = the targets written (more.zw: width, height).

float sum_of(uint base, uint k) {
    return float(g_splat_sums[pc.handles.x].s[base + k]) / SPLAT_SUM_SCALE;
}

// The ids of instance record + 1 `record` (0: none).
uvec2 record_ids(uint record) {
    return record == 0u ? uvec2(0u) : g_point_frame[pc.handles.y].instances[record - 1u].ids.xy;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.more.zw))) {
        return;
    }
    uint index = uint(p.y) * pc.more.z + uint(p.x);
    uint base = index * SPLAT_SUMS;
    if (g_splat_sums[pc.handles.x].s[base + 3u] <= int64_t(0)) {
        if (pc.handles.z == 0u) {
            imageStore(g_images_r32f[pc.outputs.z], p, vec4(0.0));
        }
        return;
    }
    vec4 cw = vec4(sum_of(base, 0u), sum_of(base, 1u), sum_of(base, 2u), sum_of(base, 3u));
    // Σw·view depth from the sum of view depths relative to the nearest word's.
    float reference = splat_view_depth(splat_nearest_depth(pc.handles.w, index), g_point_frame[pc.handles.y].depth.xy);
    vec4 nd = vec4(sum_of(base, 4u), sum_of(base, 5u), sum_of(base, 6u), sum_of(base, 7u) * reference);
    uint nearest = uint(g_splat_nearest[pc.handles.w].w[index] & uint64_t(0xffffffffu));
    uint last = g_splat_last[pc.mode.x].r[index];
    store_resolved(p, resolve_splats(cw, nd, vec2(p) + 0.5), record_ids(nearest != 0u ? nearest : last));
}
