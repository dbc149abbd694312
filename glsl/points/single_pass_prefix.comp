#version 460
// points.single_pass.prefix (dissertation §10.4): one workgroup turns the
// binning's counts into the sort's state (glsl/include/single_pass_tiles.glsl):
//   - the workgroups' entry counts into their exclusive prefix (each
//     invocation sums a run of consecutive groups, one invocation scans the
//     runs' sums): where points.single_pass.scatter writes each workgroup's
//     entries, and the frame's entries N;
//   - the entries sorted, M = min(N, capacity), and the radix sort's blocks;
//   - the key's reach bits (the key's bits − the tile index's) and the shift that
//     fits the frame's reach range (greatest − least reach bits) into them;
//   - the splats of the draws past the binned splats' buffer (not binned)
//     counted as dropped in the frame's splat counters (PointFrameStats;
//     points.single_pass.scatter counts the entries past the capacity,
//     points.single_pass.merge the rest of the lists it cut).
// Only the counts decide all of it, never the order of the GPU's invocations.
#include "../include/single_pass_radix.glsl"
#include "../include/splat_counter.glsl"

#define INVOCATIONS 256u

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, capacity (entries), counter (0xffffffff: none)
    uvec4 q;  // group buffer, groups of the frame's draws, splats of the draws not binned, key bits (whole bytes)
} pc;

shared uint s_sum[INVOCATIONS];

// a + b, saturated at 2³² − 1 (a sum past it cannot fit any capacity).
uint add_saturated(uint a, uint b) {
    uint sum = a + b;
    return sum < a ? 0xffffffffu : sum;
}

void main() {
    uint t = gl_LocalInvocationIndex;
    uint bins = pc.p.x, tiles = pc.p.y, capacity = pc.p.z;
    uint groups = pc.q.x, group_count = pc.q.y;
    uint run = (group_count + INVOCATIONS - 1u) / INVOCATIONS;
    uint first = min(t * run, group_count), end = min(first + run, group_count);
    uint sum = 0u;
    for (uint g = first; g < end; ++g) {
        sum = add_saturated(sum, g_tile_bins[groups].w[g]);
    }
    s_sum[t] = sum;
    barrier();
    if (t == 0u) {
        uint total = 0u;
        for (uint i = 0u; i < INVOCATIONS; ++i) {
            uint s = s_sum[i];
            s_sum[i] = total;
            total = add_saturated(total, s);
        }
        uint sorted = min(total, capacity);
        uint least = ~g_tile_bins[bins].w[tiles + STATE_LEAST_COMPLEMENT];
        uint greatest = g_tile_bins[bins].w[tiles + STATE_GREATEST];
        uint span = greatest >= least ? greatest - least : 0u;
        uint span_bits = span == 0u ? 0u : uint(findMSB(span)) + 1u;
        uint depth_bits = pc.q.w - (tiles > 1u ? uint(findMSB(tiles - 1u)) + 1u : 1u);
        g_tile_bins[bins].w[tiles + STATE_ENTRIES] = total;
        g_tile_bins[bins].w[tiles + STATE_SORTED] = sorted;
        g_tile_bins[bins].w[tiles + STATE_SHIFT] = span_bits > depth_bits ? span_bits - depth_bits : 0u;
        g_tile_bins[bins].w[tiles + STATE_LEAST] = greatest >= least ? least : 0u;
        g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS] = depth_bits;
        g_tile_bins[bins].w[tiles + STATE_BLOCKS] = (sorted + RADIX_BLOCK - 1u) / RADIX_BLOCK;
        uint counter = pc.p.w;
        if (counter != 0xffffffffu) {
            if (pc.q.z != 0u) {
                atomicAdd(g_splat_counters[counter].tile_entries_dropped, pc.q.z);
            }
        }
    }
    barrier();
    uint offset = s_sum[t];
    for (uint g = first; g < end; ++g) {
        uint count = g_tile_bins[groups].w[g];
        g_tile_bins[groups].w[g] = offset;
        offset = add_saturated(offset, count);
    }
}
