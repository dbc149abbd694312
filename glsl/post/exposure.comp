#version 460
// exposure.meter (§9; automatic exposure of the absolute-radiance HDR
// target), the first half of a parallel reduction: each workgroup meters a
// 128×64-pixel tile (every second pixel in x and y: plenty for a mean, a
// quarter of the reads; eight a thread, so a software rasterizer's
// workgroup barriers stay few) and writes the tile's sum of log2
// luminance and its pixel count, summed in a fixed order (deterministic
// frames). exposure.average (glsl/post/exposure_average.comp) adds the
// tiles up.
#include "../include/heap.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(set = 0, binding = 2, std430) buffer Partials { vec2 tile[]; } g_partials[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: hdr (storage rgba32f), y: partial sums (storage buffer)
    uvec4 size;     // width, height
} pc;

shared vec2 s_sum[256];

void main() {
    uint t = gl_LocalInvocationIndex;
    uvec2 origin = gl_WorkGroupID.xy * uvec2(64u, 32u) + gl_LocalInvocationID.xy;
    vec2 sum = vec2(0.0);
    for (uint j = 0u; j < 2u; ++j) {
        for (uint i = 0u; i < 4u; ++i) {
            ivec2 p = ivec2(origin + uvec2(16u * i, 16u * j)) * 2;
            if (all(lessThan(uvec2(p), pc.size.xy))) {
                vec3 c = imageLoad(g_images_rgba32f[pc.handles.x], p).rgb;
                float y = dot(max(c, vec3(0.0)), vec3(0.2126, 0.7152, 0.0722));
                // Clamp to a plausible range (1e-3 .. 1e6 cd/m²) so the sun
                // disc and unlit pixels do not dominate.
                sum += vec2(log2(clamp(y, 1e-3, 1e6)), 1.0);
            }
        }
    }
    s_sum[t] = sum;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1u) {
        if (t < stride) {
            s_sum[t] += s_sum[t + stride];
        }
        barrier();
    }
    if (t == 0u) {
        g_partials[pc.handles.y].tile[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = s_sum[0];
    }
}
