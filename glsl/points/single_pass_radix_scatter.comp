#version 460
// points.single_pass.radix_serial<k>.scatter (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one invocation per block of
// RADIX_BLOCK entries (dispatched for the capacity; blocks past the entries
// sorted return at once) walks its entries in order and writes entry j of
// digit d at d's start (points.single_pass.radix<k>.starts) + d's entries
// of the earlier blocks (its row, points.single_pass.radix<k>.scan), then
// counts it in its row: the block's entries of one digit keep their order,
// stable. The invocation owns its row: no atomics, no shared memory, no
// barrier.
#include "../include/single_pass_radix.glsl"

layout(local_size_x = RADIX_LANES) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, source entries, destination entries
    uvec4 q;  // digit positions, blocks of the capacity, digit shift, digit bits
} pc;

void main() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint block = group * RADIX_LANES + gl_LocalInvocationIndex;
    uint state = pc.p.y;
    if (block >= g_tile_bins[pc.p.x].w[state + STATE_BLOCKS]) {
        return;
    }
    uint sorted = g_tile_bins[pc.p.x].w[state + STATE_SORTED];
    uint end = min(block * RADIX_BLOCK + RADIX_BLOCK, sorted);
    uint counts = pc.q.x, shift = pc.q.z, mask = (1u << pc.q.w) - 1u;
    uint row = block * RADIX_DIGITS;
    uint starts = RADIX_DIGITS * pc.q.y;
    uint source = pc.p.z, destination = pc.p.w;
    for (uint i = block * RADIX_BLOCK; i < end; ++i) {
        TileEntry e = g_tile_entries[source].e[i];
        uint digit = (e.key >> shift) & mask;
        uint before = g_tile_bins[counts].w[row + digit];
        g_tile_bins[counts].w[row + digit] = before + 1u;
        g_tile_entries[destination].e[g_tile_bins[counts].w[starts + digit] + before] = e;
    }
}
