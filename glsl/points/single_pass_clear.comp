#version 460
// points.single_pass.clear (dissertation §10.4), interlock backend: every
// pixel's state before the splats: z_d = +inf, no sums
// (glsl/include/single_pass_merge.glsl).
#include "../include/heap.glsl"
#include "../include/single_pass_state.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 2, std430) writeonly buffer PixelWords { uvec2 w[]; } g_pixel_words[];
layout(set = 0, binding = 2, std430) writeonly buffer PixelSumsBuffer { PixelSums p[]; } g_pixel_sums[];

layout(push_constant) uniform Push {
    uvec4 handles;  // pixel words, pixel sums, pixel count, unused
} pc;

void main() {
    uint p = gl_GlobalInvocationID.x;
    if (p >= pc.handles.z) {
        return;
    }
    // Low half unused (0); high half: z_d.
    g_pixel_words[pc.handles.x].w[p] = uvec2(0u, floatBitsToUint(POSITIVE_INFINITY));
    g_pixel_sums[pc.handles.y].p[p] = PixelSums(vec4(0.0), vec4(0.0), uvec4(0u));
}
