#version 460
// points.normalize on the compute path (dissertation §10.2.3, Table 10.1
// pass 3): every pixel's sums resolved (glsl/include/splat_compute_resolve.glsl).
// Σw = 0 (no splat) keeps what the terrain and sky (or the hybrid
// triangles) wrote, and W is 0 there unless the triangles wrote it. With
// a ground on the compute path terrain.shade resolves the sums instead
// (glsl/terrain/shade_splats.comp) and this pass is not declared.
#include "../include/splat_compute_resolve.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants: handles.z = 1 to keep W where no splat is.

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.more.zw))) {
        return;
    }
    uint index = uint(p.y) * pc.more.z + uint(p.x);
    if (!resolve_splat_pixel(p, index) && pc.handles.z == 0u) {
        imageStore(g_images_r32f[pc.outputs.z], p, vec4(0.0));
    }
}
