#version 460
// exposure.average (§9), the second half of exposure.meter's reduction: one
// workgroup adds the tiles' sums in a fixed order (deterministic) into the
// mean log2 luminance of the frame and turns it into the exposure
// multiplier the tone curve applies: EV100 = log2(L_avg · S / K) with
// S = 100, K = 12.5, multiplier 1 / (1.2 · 2^EV100) (the saturation-based
// exposure of a camera), shifted by the EV compensation. A manual
// multiplier (> 0) is passed through.
#include "../include/heap.glsl"

layout(local_size_x = 256) in;

layout(set = 0, binding = 2, std430) readonly buffer Partials { vec2 tile[]; } g_partials[];
layout(set = 0, binding = 2, std430) buffer ExposureOut { float multiplier; float ev100; float mean_log2; float pad; } g_exposure[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: partial sums (storage buffer), y: exposure (storage buffer), z: tiles
    vec4 params;    // x: manual multiplier (0: automatic), y: EV compensation
} pc;

shared vec2 s_sum[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    vec2 sum = vec2(0.0);
    for (uint i = t; i < pc.handles.z; i += 256u) {
        sum += g_partials[pc.handles.x].tile[i];
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
        float mean_log2 = s_sum[0].x / max(s_sum[0].y, 1.0);
        float ev100 = mean_log2 + log2(100.0 / 12.5) - pc.params.y;
        float automatic = 1.0 / (1.2 * exp2(ev100));
        uint e = pc.handles.y;
        g_exposure[e].multiplier = pc.params.x > 0.0 ? pc.params.x : automatic;
        g_exposure[e].ev100 = pc.params.x > 0.0 ? log2(1.0 / (1.2 * pc.params.x)) : ev100;
        g_exposure[e].mean_log2 = mean_log2;
        g_exposure[e].pad = 0.0;
    }
}
