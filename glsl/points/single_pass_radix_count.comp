#version 460
// points.single_pass.radix_serial<k>.count (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one invocation per block of
// RADIX_BLOCK consecutive entries (dispatched for the capacity; blocks past
// the entries sorted return at once) counts the entries holding each value
// of the pass's digit into its block's row of the digit counts:
// counts[block × RADIX_DIGITS + digit]. The invocation owns the row: no
// atomics, no shared memory, no barrier.
#include "../include/single_pass_radix.glsl"

layout(local_size_x = RADIX_LANES) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, source entries, destination entries (unused)
    uvec4 q;  // digit counts, blocks of the capacity, digit shift, digit bits
} pc;

void main() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint block = group * RADIX_LANES + gl_LocalInvocationIndex;
    uint state = pc.p.y;
    if (block >= g_tile_bins[pc.p.x].w[state + STATE_BLOCKS]) {
        return;
    }
    uint digits = 1u << pc.q.w;
    uint row = block * RADIX_DIGITS;
    uint counts = pc.q.x;
    for (uint d = 0u; d < digits; ++d) {
        g_tile_bins[counts].w[row + d] = 0u;
    }
    uint sorted = g_tile_bins[pc.p.x].w[state + STATE_SORTED];
    uint end = min(block * RADIX_BLOCK + RADIX_BLOCK, sorted);
    uint shift = pc.q.z, mask = digits - 1u;
    for (uint i = block * RADIX_BLOCK; i < end; ++i) {
        uint digit = (g_tile_entries[pc.p.z].e[i].key >> shift) & mask;
        g_tile_bins[counts].w[row + digit] += 1u;
    }
}
