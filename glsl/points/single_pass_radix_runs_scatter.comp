#version 460
// points.single_pass.radix_runs<k>.scatter (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one workgroup per block of
// RADIX_BLOCK entries (dispatched for the capacity; blocks past the entries
// sorted return at once), each invocation owning a run of RADIX_ITEMS
// consecutive entries. Each invocation counts its run's digits into its
// own column of s_rank (16-bit halves, two digits a word); after one
// barrier, invocation i turns the rows of digits 8i … 8i + 7 into exclusive
// prefixes over the invocations (the digit's entries of the block that come
// before the run); after a second, each invocation walks its run again and
// writes entry j of digit d at the (digit, block)'s position from the scan
// + its rank. The block's entries of one digit keep their order: stable.
#define RADIX_SHARED_RUNS
#include "../include/single_pass_radix.glsl"

layout(local_size_x = 32) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, source entries, destination entries
    uvec4 q;  // digit positions (the scan's output), stride, digit shift, -
} pc;

#define WORDS (RADIX_DIGITS / 2u)
// Per invocation (column) and pair of digits: two 16-bit counts (≤ RADIX_BLOCK).
shared uint s_rank[RADIX_SCATTER_INVOCATIONS * WORDS];

void main() {
    uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint state = pc.p.y;
    if (block >= g_tile_bins[pc.p.x].w[state + STATE_BLOCKS]) {
        return;  // the whole workgroup
    }
    uint t = gl_LocalInvocationIndex;
    uint column = t * WORDS;
    for (uint w = 0u; w < WORDS; ++w) {
        s_rank[column + w] = 0u;
    }
    uint sorted = g_tile_bins[pc.p.x].w[state + STATE_SORTED];
    uint first = block * RADIX_BLOCK + t * RADIX_ITEMS;
    uint end = min(first + RADIX_ITEMS, sorted);
    uint shift = pc.q.z;
    uint source = pc.p.z;
    for (uint i = first; i < end; ++i) {
        uint digit = (g_tile_entries[source].e[i].key >> shift) & (RADIX_DIGITS - 1u);
        s_rank[column + digit / 2u] += 1u << (16u * (digit & 1u));
    }
    barrier();
    // Both halves at once: no sum exceeds RADIX_BLOCK < 2¹⁶.
    for (uint w = t * (WORDS / RADIX_SCATTER_INVOCATIONS); w < (t + 1u) * (WORDS / RADIX_SCATTER_INVOCATIONS); ++w) {
        uint before = 0u;
        for (uint i = 0u; i < RADIX_SCATTER_INVOCATIONS; ++i) {
            uint count = s_rank[i * WORDS + w];
            s_rank[i * WORDS + w] = before;
            before += count;
        }
    }
    barrier();
    uint positions = pc.q.x, stride = pc.q.y;
    for (uint i = first; i < end; ++i) {
        TileEntry e = g_tile_entries[source].e[i];
        uint digit = (e.key >> shift) & (RADIX_DIGITS - 1u);
        uint word = s_rank[column + digit / 2u];
        uint half_shift = 16u * (digit & 1u);
        s_rank[column + digit / 2u] = word + (1u << half_shift);
        uint position = g_tile_bins[positions].w[digit * stride + block] + ((word >> half_shift) & 0xffffu);
        g_tile_entries[pc.p.w].e[position] = e;
    }
}
