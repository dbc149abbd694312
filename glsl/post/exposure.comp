#version 460
// exposure.meter (§9; automatic exposure of the absolute-radiance HDR
// target): the mean log2 luminance of the frame, by one workgroup in a fixed
// order (deterministic), turned into the exposure multiplier the tone curve
// applies: EV100 = log2(L_avg · S / K) with S = 100, K = 12.5, multiplier
// 1 / (1.2 · 2^EV100) (the saturation-based exposure of a camera), shifted by
// the EV compensation. A manual multiplier (> 0) is passed through.
#include "../include/heap.glsl"

layout(local_size_x = 256) in;

layout(set = 0, binding = 2, std430) buffer ExposureOut { float multiplier; float ev100; float mean_log2; float pad; } g_exposure[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: hdr (storage rgba32f), y: exposure (storage buffer)
    uvec4 size;     // width, height
    vec4 params;    // x: manual multiplier (0: automatic), y: EV compensation
} pc;

shared float s_sum[256];
shared float s_count[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint w = pc.size.x, h = pc.size.y;
    // Every second pixel in x and y: plenty for a mean, a quarter of the reads.
    uint cols = (w + 1u) / 2u, rows = (h + 1u) / 2u;
    float sum = 0.0;
    float count = 0.0;
    for (uint i = t; i < cols * rows; i += 256u) {
        ivec2 p = ivec2((i % cols) * 2u, (i / cols) * 2u);
        vec3 c = imageLoad(g_images_rgba32f[pc.handles.x], p).rgb;
        float y = dot(max(c, vec3(0.0)), vec3(0.2126, 0.7152, 0.0722));
        // Clamp to a plausible range (1e-3 .. 1e6 cd/m²) so the sun disc and
        // unlit pixels do not dominate.
        sum += log2(clamp(y, 1e-3, 1e6));
        count += 1.0;
    }
    s_sum[t] = sum;
    s_count[t] = count;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1u) {
        if (t < stride) {
            s_sum[t] += s_sum[t + stride];
            s_count[t] += s_count[t + stride];
        }
        barrier();
    }
    if (t == 0u) {
        float mean_log2 = s_sum[0] / max(s_count[0], 1.0);
        float ev100 = mean_log2 + log2(100.0 / 12.5) - pc.params.y;
        float automatic = 1.0 / (1.2 * exp2(ev100));
        uint e = pc.handles.y;
        g_exposure[e].multiplier = pc.params.x > 0.0 ? pc.params.x : automatic;
        g_exposure[e].ev100 = pc.params.x > 0.0 ? log2(1.0 / (1.2 * pc.params.x)) : ev100;
        g_exposure[e].mean_log2 = mean_log2;
        g_exposure[e].pad = 0.0;
    }
}
