#version 460
// terrain.raster_clear (issue 28): empties a view's visibility buffer (every
// key ~0: no triangle) and its big-triangle list before terrain.raster.
#include "../include/terrain_visibility.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // -, -, visibility buffer, big-triangle list
    uvec4 size;     // pixels
} pc;

void main() {
    if (gl_GlobalInvocationID.x == 0u) {
        g_big_triangles[pc.handles.w].count = 0u;
    }
    // A grid-stride loop: at most 65535 workgroups at any image size.
    for (uint p = gl_GlobalInvocationID.x; p < pc.size.x; p += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        g_visibility[pc.handles.z].k[p] = NO_HIT;
    }
}
