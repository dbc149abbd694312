#version 460
// terrain.shadow_clear (issue 28, §9.5): every texel of the casters' depth
// buffer at 1 (nothing between the sun and the far end of the cascade),
// every cascade's big-triangle list empty.
#include "../include/terrain_shadow_raster.glsl"

layout(local_size_x = 256) in;

void main() {
    uint p = gl_GlobalInvocationID.x;
    if (p < 4u) {
        g_shadow_big[pc.handles.z].count[p] = 0u;
    }
    if (p < pc.grid.w) {
        g_shadow_depths[pc.handles.y].d[p] = floatBitsToUint(1.0);
    }
}
