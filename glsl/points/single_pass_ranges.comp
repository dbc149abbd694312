#version 460
// points.single_pass.ranges (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): after the radix sort, each tile's
// slice [first, end) of the sorted entries into its range words of the bins
// buffer (cleared to (0, 0): empty), so the merge reads its list's bounds
// instead of searching for them, and an empty tile costs it two loads. One
// workgroup per radix block of the capacity (as the sort's steps: the
// blocks past the frame's entries return at once), each invocation a run of RADIX_ITEMS_RANGES consecutive
// entries: an entry whose tile differs from the one before it starts that
// tile's slice and ends the previous tile's. Every word is written by the
// one invocation holding that boundary: the same on every run.
#include "../include/single_pass_radix.glsl"

#define INVOCATIONS 256u
#define RADIX_ITEMS_RANGES (RADIX_BLOCK / INVOCATIONS)

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, sorted entries, -
} pc;

void main() {
    uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint bins = pc.p.x, tiles = pc.p.y, entries = pc.p.z;
    uint sorted = g_tile_bins[bins].w[tiles + STATE_SORTED];
    uint depth_bits = g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS];
    uint ranges = tiles + STATE_WORDS;
    uint first = block * RADIX_BLOCK + gl_LocalInvocationIndex * RADIX_ITEMS_RANGES;
    uint end = min(first + RADIX_ITEMS_RANGES, sorted);
    if (first >= end) {
        return;  // past the entries sorted
    }
    uint previous = first == 0u ? NO_TILE : g_tile_entries[entries].e[first - 1u].key >> depth_bits;
    for (uint i = first; i < end; ++i) {
        uint tile = g_tile_entries[entries].e[i].key >> depth_bits;
        if (tile != previous) {
            g_tile_bins[bins].w[ranges + 2u * tile] = i;
            if (previous != NO_TILE) {
                g_tile_bins[bins].w[ranges + 2u * previous + 1u] = i;
            }
        }
        previous = tile;
    }
    if (end == sorted) {
        g_tile_bins[bins].w[ranges + 2u * previous + 1u] = sorted;
    }
}
