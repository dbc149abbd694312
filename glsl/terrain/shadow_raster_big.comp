#version 460
// terrain.shadow_big (issue 28, §9.5): the caster triangles terrain.shadow
// listed for a cascade, one workgroup a triangle (the workgroups loop over
// the list): a thread a row of its box within the cascade's receivers'
// region, walking the row's span of covered texels (fixed_span: exactly
// the texels the per-texel test accepts) with the depth linear along it.
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
        if (state == CASTER_FLOAT) {
            uint columns = uint(last.x - first.x + 1);
            uint texels = columns * uint(last.y - first.y + 1);
            for (uint k = gl_LocalInvocationID.x; k < texels; k += gl_WorkGroupSize.x) {
                ivec2 pixel = first + ivec2(k % columns, k / columns);
                store_caster_depth(pixel, float_caster_depth(c, z, pixel));
            }
            continue;
        }
        // By spans: a thread a row, the covered columns found exactly, the
        // depth linear along the row from its first texel's barycentrics.
        float dz_dx = 0.0;
        for (int k = 0; k < 3; ++k) {
            i64vec2 a = tri.v[(k + 1) % 3], b = tri.v[(k + 2) % 3];
            dz_dx -= float(b.y - a.y) * SUBPIXELS * z[k];
        }
        dz_dx /= float(tri.area);
        for (int y = first.y + int(gl_LocalInvocationID.x); y <= last.y; y += int(gl_WorkGroupSize.x)) {
            int x0, x1;
            if (!fixed_span(tri, y, first.x, last.x, x0, x1)) {
                continue;
            }
            vec3 lambda;
            fixed_barycentrics(tri, ivec2(x0, y), lambda);
            float z0 = dot(lambda, z);
            for (int x = x0; x <= x1; ++x) {
                store_caster_depth(ivec2(x, y), z0 + float(x - x0) * dz_dx);
            }
        }
    }
}
