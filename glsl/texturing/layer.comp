#version 460
// texturing.layer.<name> (dissertation §8.2, Table 8.1; ALGORITHMS.md §4):
// one layer of the surface-layer tree, in depth-first order, over every
// texel of every dirty tile at once: coverage from constraints, noise and the
// parent level's coverage, colour blend, displacement passed on to the next
// layer (surface_layers.glsl, the same code terrain.draw runs per pixel in
// --texturing direct).
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/surface_layers.glsl"
#include "../include/texture_tiles.glsl"

void main() {
    TileJob job;
    uvec2 local;
    vec2 xy;
    if (!tile_texel(job, local, xy)) {
        return;
    }
    uint texel = gl_GlobalInvocationID.x;
    LayerState s = unpack_state(g_texel_states[pc.handles.y].t[texel]);
    // Sample the input maps only for a layer constrained by them.
    uvec4 maps_used = pc.maps;
    for (uint k = 0u; k < 3u; ++k) {
        if (g_surface_layers[pc.handles.z].l[pc.counts.z].hats[3u + k].w == 0.0) {
            maps_used.w &= ~(1u << k);
        }
    }
    vec3 maps = input_maps(maps_used, xy / pc.extent.xy);
    BaseField field = BaseField(pc.counts.w, pc.grid.xy, pc.spacing_range.xy);
    apply_layer(pc.handles.z, pc.counts.z, pc.handles.w, xy, texel_footprint(job), pc.spacing_range.zw, maps, field, s);
    g_texel_states[pc.handles.y].t[texel] = pack_state(s);
}
