#version 460
// points.single_pass.radix_runs<k>.count (dissertation §10.4;
// glsl/include/single_pass_radix.glsl): one workgroup per block of
// RADIX_BLOCK consecutive entries (dispatched for the capacity; blocks past
// the entries sorted return at once) counts the entries holding each value
// of the pass's digit and writes the counts digit-major: counts[digit ×
// stride + block].
#define RADIX_SHARED_RUNS
#include "../include/single_pass_radix.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
    uvec4 p;  // bins, tiles, source entries, destination entries (unused)
    uvec4 q;  // digit counts, stride (blocks of the capacity), digit shift, -
} pc;

shared uint s_count[RADIX_DIGITS];

void main() {
    uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint state = pc.p.y;
    if (block >= g_tile_bins[pc.p.x].w[state + STATE_BLOCKS]) {
        return;  // the whole workgroup
    }
    uint t = gl_LocalInvocationIndex;
    s_count[t] = 0u;
    barrier();
    uint sorted = g_tile_bins[pc.p.x].w[state + STATE_SORTED];
    uint end = min(block * RADIX_BLOCK + RADIX_BLOCK, sorted);
    for (uint i = block * RADIX_BLOCK + t; i < end; i += 256u) {
        uint digit = (g_tile_entries[pc.p.z].e[i].key >> pc.q.z) & (RADIX_DIGITS - 1u);
        atomicAdd(s_count[digit], 1u);
    }
    barrier();
    g_tile_bins[pc.q.x].w[t * pc.q.y + block] = s_count[t];
}
