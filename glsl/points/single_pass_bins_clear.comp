#version 460
// points.single_pass.clear (dissertation §10.4): every tile's cut mark,
// the sort state and every tile's range 0 before points.single_pass.count
// (glsl/include/single_pass_tiles.glsl, glsl/include/single_pass_radix.glsl).
#include "../include/heap.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 2, std430) writeonly buffer TileBins { uint w[]; } g_tile_bins[];

layout(push_constant) uniform Push {
    uvec4 p;  // bins, words (cut marks, sort state, ranges), unused, unused
} pc;

void main() {
    uint tile = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    if (tile < pc.p.y) {
        g_tile_bins[pc.p.x].w[tile] = 0u;
    }
}
