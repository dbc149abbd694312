#version 460
// points.opaque.resolve on the compute path: per pixel, the splat that won
// points.opaque (the low word of the nearest word: its index in the view's
// draw table + 1) set up again and shaded at the pixel as
// glsl/points/opaque.frag shades its fragment (§10.2.2, §10.2.3's shading):
// radiance, view depth, W = 1, lighting AOVs, world normal, ids. Where no
// splat won, W is 0 unless the hybrid triangles wrote it (raster.y = 1).
#define SPLAT_RESOLVE_COMPUTE
#define SPLAT_COMPUTE
#include "../include/splat_compute_state.glsl"
#include "../include/splat_setup.glsl"
#include "../include/splat_draw_table.glsl"
#include "../include/splat_resolve.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants (splat.glsl's block): handles, mode as the splat passes;
// outputs, more: the targets; raster = (nearest words, 1: keep W where no
// splat won, -, -); draws = (draw table, draws, -, -).

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.more.zw))) {
        return;
    }
    uint index = uint(p.y) * pc.more.z + uint(p.x);
    uint winner = uint(g_splat_nearest[pc.raster.x].w[index] & uint64_t(0xffffffffu));
    SplatSetup v;
    SplatSample s;
    if (winner == 0u || frame_splat_setup(winner - 1u, v) != SPLAT_SETUP_READY ||
        !splat_sample_at(vec2(p) + 0.5, v, s)) {
        if (pc.raster.y == 0u) {
            imageStore(g_images_r32f[pc.outputs.z], p, vec4(0.0));
        }
        return;
    }
    ResolvedSplats r;
    r.radiance = vec4(shade_splat(v.color.rgb, v.normal.xyz, s.position, r.visibility), 1.0);
    r.view_depth = -s.position.z;
    r.weight = 1.0;
    r.normal = world_normal(v.normal.xyz, s.position);
    store_resolved(p, r, g_point_frame[pc.handles.y].instances[splat_record].ids.xy);
}
