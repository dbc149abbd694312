#version 460
// points.single_pass.radix_serial<k>.starts (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one workgroup turns the digits'
// totals (after the blocks' rows) into each digit's first output position,
// in place: each invocation sums a run of RADIX_DIGITS / 256 digits,
// invocation 0 scans the 256 sums, each invocation writes its run's starts.
#include "../include/single_pass_radix.glsl"

#define INVOCATIONS 256u
#define RUN (RADIX_DIGITS / INVOCATIONS)

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, -, -
    uvec4 q;  // digit counts, blocks of the capacity, -, -
} pc;

shared uint s_start[INVOCATIONS];

void main() {
    uint t = gl_LocalInvocationIndex;
    uint counts = pc.q.x;
    uint first = RADIX_DIGITS * pc.q.y + t * RUN;
    uint sum = 0u;
    for (uint i = 0u; i < RUN; ++i) {
        sum += g_tile_bins[counts].w[first + i];
    }
    s_start[t] = sum;
    barrier();
    if (t == 0u) {
        uint start = 0u;
        for (uint i = 0u; i < INVOCATIONS; ++i) {
            uint count = s_start[i];
            s_start[i] = start;
            start += count;
        }
    }
    barrier();
    uint position = s_start[t];
    for (uint i = 0u; i < RUN; ++i) {
        uint count = g_tile_bins[counts].w[first + i];
        g_tile_bins[counts].w[first + i] = position;
        position += count;
    }
}
