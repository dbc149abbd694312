#version 460
// points.single_pass.scatter (dissertation §10.4): one invocation per splat
// of the draw (the dispatches of points.single_pass.count again), no shared
// memory and no barrier: each splat's entries (sort key, slot, the tile's
// blocks its box touches; glsl/include/single_pass_tiles.glsl), one per
// tile in row order, written from its workgroup's offset
// (points.single_pass.prefix) + the entries of the workgroup's earlier
// invocations (points.single_pass.count kept their sum in the splat's
// BinnedSplat): positions fixed by the draws' order, the same on every
// run; none at or past the capacity (their tiles marked cut, the entries
// counted as dropped).
#define SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS_BIN
#include "../include/single_pass_tiles.glsl"

layout(local_size_x = 64) in;

// Push constants (the splat passes' block, splat.glsl), as points.single_pass.count's:
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   mode.w = the draw's instance record,
//   single = (bins, entries, -, splats of the draw),
//   bin = (group buffer: each workgroup's first entry, the draw's first
//          workgroup in it, binned splats, -).

void scatter(uint group, uint index, uint slot) {
    uint bins = pc.single.x;
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    uvec4 box = index < pc.single.w ? g_binned_splats[pc.bin.z].s[slot].box : uvec4(NOT_BINNED);
    bool binned = box.x != NOT_BINNED;
    uvec2 first = uvec2(box.x & 0xffffu, box.x >> 16), last = uvec2(box.y & 0xffffu, box.y >> 16);
    uvec2 lo = first / TILE_SIZE, hi = last / TILE_SIZE + 1u;
    if (!binned) {
        return;
    }
    // The entries of the workgroup's earlier invocations (the count pass's sum).
    uint before = box.w;
    uint start = g_tile_bins[pc.bin.x].w[pc.bin.y + group];
    uint position = start + before;
    // Saturated: a sum past 2³² − 1 cannot fit any capacity anyway.
    position = position < start ? 0xffffffffu : position;
    uint capacity = g_tile_bins[bins].w[tiles + STATE_SORTED];
    uint least = g_tile_bins[bins].w[tiles + STATE_LEAST];
    uint shift = g_tile_bins[bins].w[tiles + STATE_SHIFT];
    uint depth_bits = g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS];
    uint reach = (box.z - least) >> shift;
    for (uint y = lo.y; y < hi.y; ++y) {
        for (uint x = lo.x; x < hi.x; ++x) {
            if (position >= capacity) {
                // Past the capacity: the tile's list is cut (the merge
                // drops it whole), the entry counted as dropped.
                atomicOr(g_tile_bins[bins].w[y * grid.x + x], 1u);
                if (pc.handles.z != NO_HANDLE) {
                    atomicAdd(g_splat_counters[pc.handles.z].tile_entries_dropped, 1u);
                }
                position += position == 0xffffffffu ? 0u : 1u;
                continue;
            }
            uint key = ((y * grid.x + x) << depth_bits) | reach;
            uint blocks = tile_blocks(first, last, uvec2(x, y) * TILE_SIZE);
            g_tile_entries[pc.single.y].e[position] = TileEntry(key, slot, blocks);
            position += 1u;
        }
    }
}

void main() {
    // Dispatches wider than the 65535-workgroup limit use rows of workgroups.
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint index = group * BIN_WORKGROUP_SIZE + gl_LocalInvocationIndex;
    uint slot = (pc.bin.y + group) * BIN_WORKGROUP_SIZE + gl_LocalInvocationIndex;
    scatter(group, index, slot);
}
