#version 460
// points.single_pass.radix_serial<k>.scan (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one invocation per digit value
// turns its column of the blocks' digit counts (block-major rows) into the
// exclusive prefix over the blocks (the digit's entries of the earlier
// blocks) and writes the digit's total after the rows. The eight digits of
// a SIMD row read one row's neighbouring words.
#include "../include/single_pass_radix.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, -, -
    uvec4 q;  // digit counts, blocks of the capacity, -, digit bits
} pc;

void main() {
    uint d = gl_GlobalInvocationID.x;
    uint counts = pc.q.x;
    uint totals = RADIX_DIGITS * pc.q.y;
    if (d >= (1u << pc.q.w)) {
        g_tile_bins[counts].w[totals + d] = 0u;
        return;
    }
    uint blocks = g_tile_bins[pc.p.x].w[pc.p.y + STATE_BLOCKS];
    uint sum = 0u;
    for (uint b = 0u; b < blocks; ++b) {
        uint count = g_tile_bins[counts].w[b * RADIX_DIGITS + d];
        g_tile_bins[counts].w[b * RADIX_DIGITS + d] = sum;
        sum += count;
    }
    g_tile_bins[counts].w[totals + d] = sum;
}
