#version 460
// points.single_pass.prefix (dissertation §10.4): one workgroup scans the
// tiles' counts in tile order (256 tiles a step, carried over), giving each
// tile its list's offset in the entry buffer, its kept length and a cursor
// of 0 (glsl/include/single_pass_tiles.glsl). A list that would end beyond
// the buffer's capacity is dropped whole (kept = 0), and so is every later
// one: which entries are lost depends only on the counts, never on the
// order of the GPU's invocations. The dropped entries and the longest list
// are added to the frame's splat counters (PointFrameStats).
#include "../include/heap.glsl"
#include "../include/splat_counter.glsl"

layout(local_size_x = 256) in;

layout(set = 0, binding = 2, std430) buffer TileBins { uint w[]; } g_tile_bins[];

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, capacity (entries), counter (0xffffffff: none)
} pc;

shared uint s_scan[256];
shared uint s_carry;

void main() {
    uint t = gl_LocalInvocationIndex;
    uint bins = pc.p.x, tiles = pc.p.y, capacity = pc.p.z;
    if (t == 0u) {
        s_carry = 0u;
    }
    uint dropped = 0u;
    uint longest = 0u;
    for (uint base = 0u; base < tiles; base += 256u) {
        uint tile = base + t;
        uint count = tile < tiles ? g_tile_bins[bins].w[tile] : 0u;
        s_scan[t] = count;
        barrier();
        for (uint d = 1u; d < 256u; d <<= 1u) {
            uint add = t >= d ? s_scan[t - d] : 0u;
            barrier();
            s_scan[t] += add;
            barrier();
        }
        // Saturating: a sum past 2³² − 1 cannot fit any capacity anyway.
        uint carry = s_carry;
        uint inclusive = carry + s_scan[t];
        inclusive = inclusive < carry ? 0xffffffffu : inclusive;
        if (tile < tiles) {
            bool fits = inclusive <= capacity;
            g_tile_bins[bins].w[tiles + tile] = inclusive - count;
            g_tile_bins[bins].w[2u * tiles + tile] = fits ? count : 0u;
            g_tile_bins[bins].w[3u * tiles + tile] = 0u;
            dropped += fits ? 0u : count;
            longest = max(longest, count);
        }
        barrier();
        if (t == 255u) {
            s_carry = inclusive;
        }
        barrier();
    }
    uint counter = pc.p.w;
    if (counter != 0xffffffffu) {
        if (dropped > 0u) {
            atomicAdd(g_splat_counters[counter].tile_entries_dropped, dropped);
        }
        atomicMax(g_splat_counters[counter].longest_tile_list, longest);
    }
}
