#version 460
// synthesis.accept (§7.3): per query the smallest choice hash among the
// accepted candidates, s(c) ≤ (1 + ε)·best (a workgroup minimum, then one
// atomicMin per workgroup). One workgroup per query (y) and 256 candidates
// (x; blocks beyond the dispatch loop).
#include "../include/synthesis_search.glsl"

layout(local_size_x = 256) in;

shared uint s_hash;

void main() {
    uint q = gl_WorkGroupID.y;
    uint candidates = pc.sizes.y;
    uint blocks = (candidates + 255u) / 256u;
    uint pixel = g_synthesis_uints[pc.inputs.w].u[q];
    float threshold = synthesis_threshold(pc.outputs.y, q);
    uint hash = SYNTHESIS_NONE;
    for (uint block = gl_WorkGroupID.x; block < blocks; block += gl_NumWorkGroups.x) {
        uint c = block * 256u + gl_LocalInvocationID.x;
        if (c < candidates && g_synthesis_sums[pc.outputs.x].s[q * candidates + c] <= threshold) {
            hash = min(hash, choice_hash(pc.rule.x, pixel, c));
        }
    }
    if (gl_LocalInvocationID.x == 0u) {
        s_hash = SYNTHESIS_NONE;
    }
    barrier();
    atomicMin(s_hash, hash);
    barrier();
    if (gl_LocalInvocationID.x == 0u && s_hash != SYNTHESIS_NONE) {
        atomicMin(g_synthesis_results[pc.outputs.y].r[q].y, s_hash);
    }
}
