#version 460
// texturing.upsample (dissertation §8.2, root upsampling; ALGORITHMS.md §4):
// every texel of every dirty tile gets the base surface, the height field
// as a cubic B-spline (bspline_height.glsl, shared with terrain.warp and
// terrain.draw), at its world position: height and slope start the
// per-layer passes.
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/bspline_height.glsl"
#include "../include/surface_layers.glsl"
#include "../include/texture_tiles.glsl"

void main() {
    TileJob job;
    uvec2 local;
    vec2 xy;
    if (!tile_texel(job, local, xy)) {
        return;
    }
    vec2 grad;
    float h = bspline_height(pc.counts.w, pc.grid.xy, pc.spacing_range.xy, xy, grad);
    g_texel_states[pc.handles.y].t[gl_GlobalInvocationID.x] = pack_state(layer_state(h, grad));
}
