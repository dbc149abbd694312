#version 460
// synthesis.resolve (§7.3): per query the picked candidate (0 when nothing
// was accepted, as on the CPU), its s and the key of the best s, into the
// host-visible readback buffer (the host normalises by Σ w).
#include "../include/synthesis_search.glsl"

layout(set = 0, binding = 2, std430) writeonly buffer SynthesisReadback { uvec4 r[]; } g_synthesis_readback[];

layout(local_size_x = 64) in;

void main() {
    uint q = gl_GlobalInvocationID.x;
    if (q >= pc.sizes.x) {
        return;
    }
    uvec4 result = g_synthesis_results[pc.outputs.y].r[q];
    uint pick = result.z == SYNTHESIS_NONE ? 0u : result.z;
    float s = g_synthesis_sums[pc.outputs.x].s[q * pc.sizes.y + pick];
    g_synthesis_readback[pc.outputs.z].r[q] = uvec4(pick, floatBitsToUint(s), result.x, 0u);
}
