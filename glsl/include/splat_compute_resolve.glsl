// The compute path's normalization of splat sums (dissertation §10.2.3,
// Table 10.1 pass 3), shared by points.normalize
// (glsl/points/compute_normalize.comp) and terrain.shade when it shades
// the points with the ground (glsl/terrain/shade_splats.comp): a pixel's
// fixed-point sums of points.accumulate (splat_compute_state.glsl) divided
// and shaded as the hardware path's points.normalize (splat_resolve.glsl).
// The ids are those of the splat that won the visibility pass, or where
// none did (its pushed-back depth lost against the ground's, the surface
// is in front of it) of the last splat accumulated.
//
// Push constants (the splat passes' block, splat.glsl, with
// SPLAT_RESOLVE_COMPUTE): handles = (sums, point frame, -, nearest words),
// mode.x = last records, outputs and more = the targets written.
#ifndef ALPENGLOW_SPLAT_COMPUTE_RESOLVE_GLSL
#define ALPENGLOW_SPLAT_COMPUTE_RESOLVE_GLSL

#define SPLAT_RESOLVE_COMPUTE
#include "splat_compute_state.glsl"
#include "splat_resolve.glsl"

float splat_sum_of(uint base, uint k) {
    return float(g_splat_sums[pc.handles.x].s[base + k]) / SPLAT_SUM_SCALE;
}

// The ids of instance record + 1 `record` (0: none).
uvec2 splat_record_ids(uint record) {
    return record == 0u ? uvec2(0u) : g_point_frame[pc.handles.y].instances[record - 1u].ids.xy;
}

// Resolves and stores pixel `p` (index `index` in the buffers) when
// splats cover it (Σw > 0); false, nothing written, when none does.
bool resolve_splat_pixel(ivec2 p, uint index) {
    uint base = index * SPLAT_SUMS;
    if (g_splat_sums[pc.handles.x].s[base + 3u] <= int64_t(0)) {
        return false;
    }
    vec4 cw = vec4(splat_sum_of(base, 0u), splat_sum_of(base, 1u), splat_sum_of(base, 2u), splat_sum_of(base, 3u));
    // Σw·view depth from the sum of view depths relative to the nearest word's.
    float reference = splat_view_depth(splat_nearest_depth(pc.handles.w, index), g_point_frame[pc.handles.y].depth.xy);
    vec4 nd = vec4(splat_sum_of(base, 4u), splat_sum_of(base, 5u), splat_sum_of(base, 6u),
                   splat_sum_of(base, 7u) * reference);
    uint nearest = uint(g_splat_nearest[pc.handles.w].w[index] & uint64_t(0xffffffffu));
    uint last = g_splat_last[pc.mode.x].r[index];
    store_resolved(p, resolve_splats(cw, nd, vec2(p) + 0.5), splat_record_ids(nearest != 0u ? nearest : last));
    return true;
}

#endif
