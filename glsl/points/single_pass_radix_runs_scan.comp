#version 460
// points.single_pass.radix_runs<k>.scan (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one workgroup, one invocation per
// digit value, turns the blocks' digit counts (digit-major) into the first
// output position of each (digit, block): invocation d sums its digit's row,
// invocation 0 scans the 256 sums, and each invocation writes its row's
// exclusive prefix from its digit's start.
#define RADIX_SHARED_RUNS
#include "../include/single_pass_radix.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, -, -
    uvec4 q;  // digit counts, stride (blocks of the capacity), -, -
} pc;

shared uint s_start[RADIX_DIGITS];

void main() {
    uint d = gl_LocalInvocationIndex;
    uint blocks = g_tile_bins[pc.p.x].w[pc.p.y + STATE_BLOCKS];
    uint row = d * pc.q.y;
    uint sum = 0u;
    for (uint b = 0u; b < blocks; ++b) {
        sum += g_tile_bins[pc.q.x].w[row + b];
    }
    s_start[d] = sum;
    barrier();
    if (d == 0u) {
        uint start = 0u;
        for (uint i = 0u; i < RADIX_DIGITS; ++i) {
            uint count = s_start[i];
            s_start[i] = start;
            start += count;
        }
    }
    barrier();
    uint position = s_start[d];
    for (uint b = 0u; b < blocks; ++b) {
        uint count = g_tile_bins[pc.q.x].w[row + b];
        g_tile_bins[pc.q.x].w[row + b] = position;
        position += count;
    }
}
