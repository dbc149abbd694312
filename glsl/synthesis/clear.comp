#version 460
// synthesis.clear (§7.3): every query of the batch starts with best = +∞,
// no accepted hash and no pick.
#include "../include/synthesis_search.glsl"

layout(local_size_x = 64) in;

void main() {
    uint q = gl_GlobalInvocationID.x;
    if (q < pc.sizes.x) {
        g_synthesis_results[pc.outputs.y].r[q] = uvec4(SYNTHESIS_KEY_INFINITY, SYNTHESIS_NONE, SYNTHESIS_NONE, 0u);
    }
}
