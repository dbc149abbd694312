#version 460
// points.single_pass.count and points.single_pass.scatter (dissertation
// §10.4): one invocation per splat of the draw (one dispatch per planned
// draw), the EWA set-up of glsl/include/splat_setup.glsl, then its bounding
// box's tiles (glsl/include/single_pass_tiles.glsl):
//   phase 0 (count):   each tile's count += 1; the splats passing the
//                      interval test and drawn are counted as in every mode;
//   phase 1 (scatter): the entry (depth key, record, index) written at the
//                      tile's offset + atomicAdd(cursor), only while the
//                      cursor is below the tile's kept length (lists that did
//                      not fit the entry buffer are dropped whole by
//                      points.single_pass.prefix, never written out of bounds).
// Both phases run this one pipeline, so both see the same set-ups and boxes.
#define SPLAT_SINGLE_PASS
#include "../include/single_pass_tiles.glsl"

#define WORKGROUP_SIZE 64u
#define PHASE_COUNT 0u

layout(local_size_x = 64) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   mode.w = the draw's instance record,
//   single = (bins, entries, phase, splats of the draw).

void main() {
    // Dispatches wider than the 65535-workgroup limit use rows of workgroups.
    uint index = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * WORKGROUP_SIZE + gl_LocalInvocationIndex;
    if (index >= pc.single.w) {
        return;
    }
    SplatSetup v;
    uint setup = splat_setup(index, v);
    bool counting = pc.single.z == PHASE_COUNT;
    if (counting && pc.handles.z != NO_HANDLE && setup != SPLAT_SETUP_OUTSIDE_INTERVAL) {
        atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
        if (setup == SPLAT_SETUP_READY) {
            atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
        }
    }
    uvec2 lo, hi;
    if (setup != SPLAT_SETUP_READY || !splat_tiles(v, lo, hi)) {
        return;
    }
    uint bins = pc.single.x;
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    TileEntry entry = TileEntry(splat_depth_key(v), pc.mode.w, index);
    for (uint y = lo.y; y < hi.y; ++y) {
        for (uint x = lo.x; x < hi.x; ++x) {
            uint tile = y * grid.x + x;
            if (counting) {
                atomicAdd(g_tile_bins[bins].w[tile], 1u);
                continue;
            }
            uint slot = atomicAdd(g_tile_bins[bins].w[3u * tiles + tile], 1u);
            if (slot < g_tile_bins[bins].w[2u * tiles + tile]) {
                g_tile_entries[pc.single.y].e[g_tile_bins[bins].w[tiles + tile] + slot] = entry;
            }
        }
    }
}
