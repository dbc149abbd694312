#version 460
// points.single_pass, interlock backend (dissertation §10.4;
// VK_EXT_fragment_shader_interlock, fragmentShaderPixelInterlock): the
// splats drawn as in the three-pass mode (glsl/points/splat.vert), each
// fragment merged into the same pixel state as the compute backend
// (glsl/include/single_pass_merge.glsl) inside a pixel-ordered critical
// section: merges follow primitive order, so the result is deterministic.
#extension GL_ARB_fragment_shader_interlock : require
#define SPLAT_SINGLE_PASS
#include "../include/splat_fragment.glsl"
#include "../include/single_pass_merge.glsl"

layout(pixel_interlock_ordered) in;

// W is the pass's attachment only to give the rasteriser its area: every
// fragment is discarded after its merge, so W keeps what it held.

void main() {
    SplatSample s;
    SplatFragment frag;
    bool inside = splat_sample(s) && single_pass_fragment(splat_varyings(), s, uvec2(gl_FragCoord.xy), frag);
    beginInvocationInterlockARB();
    if (inside) {
        uint depth = 2u * frag.pixel + 1u;
        float zd = uintBitsToFloat(g_pixel_words32[pc.single.x].w[depth]);
        if (frag.z < zd + frag.zf) {
            g_pixel_words32[pc.single.x].w[depth] = floatBitsToUint(merge_locked(frag, zd));
        }
    }
    endInvocationInterlockARB();
    discard;
}
