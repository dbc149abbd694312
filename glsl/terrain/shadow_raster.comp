#version 460
// terrain.shadow (the compute path's shadow casters, §9.5; issue 28): one
// thread a grid triangle, one dispatch a cascade. A triangle outside the
// cascade's quadrant or depth range is culled; one with more than
// SHADOW_BIG_PIXELS of bounding box (or beyond the fixed-point range) is
// listed for terrain.shadow_big; the rest are rasterized here with
// terrain.raster's fixed-point edge functions and tie rule, the depth
// interpolated linearly (the cascades are orthographic).
#include "../include/terrain_shadow_raster.glsl"

layout(local_size_x = 64) in;

void cast_triangle(uint t) {
    vec4 c[3];
    FixedTriangle tri;
    vec3 z;
    ivec2 first, last;
    int state = setup_caster(t, c, tri, z, first, last);
    if (state == CASTER_CULLED) {
        return;
    }
    if (state == CASTER_FLOAT || uint(last.x - first.x + 1) * uint(last.y - first.y + 1) > SHADOW_BIG_PIXELS) {
        list_big_caster(t);
        return;
    }
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            store_caster_depth(ivec2(x, y), fixed_caster_depth(tri, z, ivec2(x, y)));
        }
    }
}

// A grid-stride loop: the dispatch stays within maxComputeWorkGroupCount
// (65535 workgroups) at any grid size.
void main() {
    for (uint t = gl_GlobalInvocationID.x; t < pc.grid.y; t += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
        cast_triangle(t);
    }
}
