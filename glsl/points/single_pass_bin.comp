#version 460
// points.single_pass.count and points.single_pass.scatter (dissertation
// §10.4): one invocation per splat of the draw (one dispatch per planned
// draw), the EWA set-up of glsl/include/splat_setup.glsl, then its bounding
// box's tiles (glsl/include/single_pass_tiles.glsl):
//   phase 0 (count):   each tile's count += 1, the least and greatest depth
//                      kept (reduced per workgroup), the workgroup's entries (the sum of its splats'
//                      tiles) written to its word of the group buffer; the
//                      splats passing the interval test and drawn are
//                      counted as in every mode;
//   phase 1 (scatter): each splat's entries (sort key, record, index), one
//                      per tile in row order, written from its workgroup's
//                      offset (points.single_pass.prefix) + the exclusive
//                      sum of the entries of the workgroup's earlier
//                      invocations: positions fixed by the draws' order, the
//                      same on every run; none at or past the capacity.
// Both phases run this one pipeline, so both see the same set-ups and boxes.
#define SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS_BIN
#include "../include/single_pass_tiles.glsl"

#define WORKGROUP_SIZE 64u
#define PHASE_COUNT 0u

layout(local_size_x = 64) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   mode.w = the draw's instance record,
//   single = (bins, entries, phase, splats of the draw),
//   bin = (group buffer: one word per workgroup of the frame's draws, the
//          draw's first workgroup in it, -, -).

shared uint s_entries[WORKGROUP_SIZE];
// Each invocation's ~(depth bits) and depth bits (0: not binned, a no-op
// for the atomicMax below), reduced once per workgroup: two atomics a
// workgroup on the frame's depth range, not two a splat.
shared uint s_least_complement[WORKGROUP_SIZE];
shared uint s_greatest[WORKGROUP_SIZE];

void main() {
    // Dispatches wider than the 65535-workgroup limit use rows of workgroups.
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint index = group * WORKGROUP_SIZE + gl_LocalInvocationIndex;
    bool counting = pc.single.z == PHASE_COUNT;
    uint groups = pc.bin.x;
    uint bins = pc.single.x;
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    // No early return: the workgroup meets at the barrier below.
    SplatSetup v;
    uvec2 lo = uvec2(0u), hi = uvec2(0u);
    bool binned = false;
    if (index < pc.single.w) {
        uint setup = splat_setup(index, v);
        if (counting && pc.handles.z != NO_HANDLE && setup != SPLAT_SETUP_OUTSIDE_INTERVAL) {
            atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
            if (setup == SPLAT_SETUP_READY) {
                atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
            }
        }
        binned = setup == SPLAT_SETUP_READY && splat_tiles(v, lo, hi);
    }
    uvec2 box = binned ? hi - lo : uvec2(0u);
    s_entries[gl_LocalInvocationIndex] = box.x * box.y;
    uint bits = binned ? splat_depth_bits(v) : 0u;
    s_least_complement[gl_LocalInvocationIndex] = binned ? ~bits : 0u;
    s_greatest[gl_LocalInvocationIndex] = bits;
    barrier();
    uint first_group = pc.bin.y;
    bool in_draw = group * WORKGROUP_SIZE < pc.single.w;
    if (counting) {
        if (gl_LocalInvocationIndex == 0u && in_draw) {
            uint sum = 0u;
            for (uint i = 0u; i < WORKGROUP_SIZE; ++i) {
                sum += s_entries[i];
            }
            g_tile_bins[groups].w[first_group + group] = sum;
            uint least_complement = 0u, greatest = 0u;
            for (uint i = 0u; i < WORKGROUP_SIZE; ++i) {
                least_complement = max(least_complement, s_least_complement[i]);
                greatest = max(greatest, s_greatest[i]);
            }
            if (least_complement != 0u || greatest != 0u) {
                atomicMax(g_tile_bins[bins].w[tiles + STATE_LEAST_COMPLEMENT], least_complement);
                atomicMax(g_tile_bins[bins].w[tiles + STATE_GREATEST], greatest);
            }
        }
        if (!binned) {
            return;
        }
        for (uint y = lo.y; y < hi.y; ++y) {
            for (uint x = lo.x; x < hi.x; ++x) {
                atomicAdd(g_tile_bins[bins].w[y * grid.x + x], 1u);
            }
        }
        return;
    }
    if (!binned) {
        return;
    }
    uint position = g_tile_bins[groups].w[first_group + group];
    for (uint i = 0u; i < gl_LocalInvocationIndex; ++i) {
        position += s_entries[i];
    }
    // Saturated: a sum past 2³² − 1 cannot fit any capacity anyway.
    position = position < g_tile_bins[groups].w[first_group + group] ? 0xffffffffu : position;
    uint capacity = g_tile_bins[bins].w[tiles + STATE_SORTED];
    uint least = g_tile_bins[bins].w[tiles + STATE_LEAST];
    uint shift = g_tile_bins[bins].w[tiles + STATE_SHIFT];
    uint depth_bits = g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS];
    uint depth = (splat_depth_bits(v) - least) >> shift;
    for (uint y = lo.y; y < hi.y; ++y) {
        for (uint x = lo.x; x < hi.x; ++x) {
            if (position >= capacity) {
                return;
            }
            uint key = ((y * grid.x + x) << depth_bits) | depth;
            g_tile_entries[pc.single.y].e[position] = TileEntry(key, pc.mode.w, index);
            position += 1u;
        }
    }
}
