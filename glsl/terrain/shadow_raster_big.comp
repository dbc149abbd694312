#version 460
// terrain.shadow_big (issue 28, §9.5): the caster triangles terrain.shadow
// listed for a cascade, one workgroup a triangle (the workgroups loop over
// the list), its threads striding over the texels of its box within the
// cascade's quadrant.
#include "../include/terrain_shadow_raster.glsl"

layout(local_size_x = 64) in;

void main() {
    uint cascade = pc.handles.w;
    uint count = g_shadow_big[pc.handles.z].count[cascade];
    for (uint b = gl_WorkGroupID.x; b < count; b += gl_NumWorkGroups.x) {
        uint t = g_shadow_big[pc.handles.z].ids[cascade * pc.grid.y + b];
        vec4 c[3];
        FixedTriangle tri;
        vec3 z;
        ivec2 first, last;
        int state = setup_caster(t, c, tri, z, first, last);
        if (state == CASTER_CULLED) {
            continue;
        }
        uint columns = uint(last.x - first.x + 1);
        uint texels = columns * uint(last.y - first.y + 1);
        for (uint k = gl_LocalInvocationID.x; k < texels; k += gl_WorkGroupSize.x) {
            ivec2 pixel = first + ivec2(k % columns, k / columns);
            float depth = state == CASTER_FIXED ? fixed_caster_depth(tri, z, pixel) : float_caster_depth(c, z, pixel);
            store_caster_depth(pixel, depth);
        }
    }
}
