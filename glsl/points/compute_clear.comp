#version 460
// points.clear on the compute path (dissertation §10.2.3): every pixel's
// splat state before the visibility pass (glsl/include/splat_compute_state.glsl):
// the nearest word holds the depth buffer's depth (terrain, hybrid
// triangles; the far depth where nothing drew) — or, with the terrain on
// the compute path, the depth of its visibility key's view depth — and no
// splat, the sums and the last record are 0.
#include "../include/splat_compute_state.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // nearest words, sums and last records (NO_HANDLE: opaque splats), depth buffer (sampled; NO_HANDLE: far)
    uvec4 size;     // width, height, the ground's visibility keys (NO_HANDLE: none), -
    vec4 row;       // the point frame's depth row (P22, P32): view depth → depth
} pc;

layout(set = 0, binding = 2, std430) readonly buffer GroundKeys { uint64_t k[]; } g_ground_keys[];

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
    if (pc.size.z != NO_HANDLE) {
        // glsl/include/terrain_visibility.glsl: the view depth's bits high, all ones where nothing drew.
        uint64_t key = g_ground_keys[pc.size.z].k[p];
        if (key != ~uint64_t(0)) {
            // depth = (P22·z + P32)/−z at z = −view depth (splat.glsl's depth_of).
            float view_depth = uintBitsToFloat(uint(key >> 32));
            depth = max(pc.row.y / view_depth - pc.row.x, FAR_DEPTH);
        }
    }
    g_splat_nearest[pc.handles.x].w[p] = uint64_t(floatBitsToUint(depth)) << 32;
    if (pc.handles.y == NO_HANDLE) {
        return;  // opaque splats: no sums
    }
    for (uint k = 0u; k < SPLAT_SUMS; ++k) {
        g_splat_sums[pc.handles.y].s[p * SPLAT_SUMS + k] = int64_t(0);
    }
    g_splat_last[pc.handles.z].r[p] = 0u;
}
