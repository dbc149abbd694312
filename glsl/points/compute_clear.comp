#version 460
// points.clear on the compute path (dissertation §10.2.3): every pixel's
// splat state before the visibility pass (glsl/include/splat_compute_state.glsl):
// the nearest word holds the depth buffer's depth (terrain, hybrid
// triangles; the far depth where nothing drew) and no splat, the sums and
// the last record are 0.
#include "../include/splat_compute_state.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // nearest words, sums, last records, depth buffer (sampled; NO_HANDLE: far)
    uvec4 size;     // width, height
} pc;

#define NO_HANDLE 0xffffffffu
const float FAR_DEPTH = 0.0;  // reversed depth (src/view/depth.rs)

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, pc.size.xy))) {
        return;
    }
    uint p = pixel.y * pc.size.x + pixel.x;
    float depth = FAR_DEPTH;
    if (pc.handles.w != NO_HANDLE) {
        depth = texelFetch(sampler2D(g_textures[pc.handles.w], g_samplers[SAMPLER_NEAREST_CLAMP]), ivec2(pixel), 0).r;
    }
    g_splat_nearest[pc.handles.x].w[p] = uint64_t(floatBitsToUint(depth)) << 32;
    for (uint k = 0u; k < SPLAT_SUMS; ++k) {
        g_splat_sums[pc.handles.y].s[p * SPLAT_SUMS + k] = int64_t(0);
    }
    g_splat_last[pc.handles.z].r[p] = 0u;
}
