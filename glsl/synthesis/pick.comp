#version 460
// synthesis.pick (§7.3): per query the smallest accepted candidate whose
// hash is the smallest one (the rule's key is (hash, candidate)). Same
// dispatch as synthesis.accept.
#include "../include/synthesis_search.glsl"

layout(local_size_x = 256) in;

void main() {
    uint q = gl_WorkGroupID.y;
    uint candidates = pc.sizes.y;
    uint blocks = (candidates + 255u) / 256u;
    uint pixel = g_synthesis_uints[pc.inputs.w].u[q];
    float threshold = synthesis_threshold(pc.outputs.y, q);
    uint smallest = g_synthesis_results[pc.outputs.y].r[q].y;
    for (uint block = gl_WorkGroupID.x; block < blocks; block += gl_NumWorkGroups.x) {
        uint c = block * 256u + gl_LocalInvocationID.x;
        if (c < candidates && choice_hash(pc.rule.x, pixel, c) == smallest &&
            g_synthesis_sums[pc.outputs.x].s[q * candidates + c] <= threshold) {
            atomicMin(g_synthesis_results[pc.outputs.y].r[q].z, c);
        }
    }
}
