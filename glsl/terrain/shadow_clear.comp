#version 460
// terrain.shadow_clear (issue 28, §9.5): every texel of the casters' depth
// buffer at 1 (nothing between the sun and the far end of the cascade),
// every cascade's big-triangle list empty.
#include "../include/terrain_shadow_raster.glsl"

layout(local_size_x = 256) in;

void main() {
    if (gl_GlobalInvocationID.x < 4u) {
        g_shadow_big[pc.handles.z].count[gl_GlobalInvocationID.x] = 0u;
    }
    // A grid-stride loop: at most 65535 workgroups at any atlas size.
    for (uint p = gl_GlobalInvocationID.x; p < pc.grid.w; p += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        g_shadow_depths[pc.handles.y].d[p] = floatBitsToUint(1.0);
    }
}
