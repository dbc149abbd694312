#version 460
// texturing.upsample (dissertation §8.2, root upsampling; ALGORITHMS.md §4):
// every texel of every dirty tile gets the base surface terrain.warp draws,
// the height field as a cubic B-spline blended into the streamed detail
// window where it is drawn (detail_window.glsl's detail_surface, shared
// with terrain.warp and direct texturing), at its world position: height
// and slope start the per-layer passes.
#define TEXTURE_TILES_DETAIL_WINDOW
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/bspline_height.glsl"
#include "../include/detail_window.glsl"
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
    float window;
    float h = detail_surface(pc.window, pc.counts.w, pc.grid.xy, pc.spacing_range.xy, xy, grad, window);
    g_texel_states[pc.handles.y].t[gl_GlobalInvocationID.x] = pack_state(layer_state(h, grad));
}
