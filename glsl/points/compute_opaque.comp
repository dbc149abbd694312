#version 460
// points.opaque on the compute path (the opaque baseline of §10.2.2 as in
// glsl/points/opaque.frag: the cut-off ellipse of each splat, ray–plane
// depth, no blending): each fragment raises the pixel's nearest word
// (glsl/include/splat_compute_state.glsl) with its depth — not pushed back —
// and the splat's index in the view's draw table + 1. atomicMax keeps the
// nearest splat whatever the order (ties: the higher index), and
// points.opaque.resolve shades the one that won.
#include "../include/splat_compute.glsl"

void splat_pixel(SplatSetup v, uvec2 pixel) {
    SplatSample s;
    if (!splat_sample_at(vec2(pixel) + 0.5, v, s)) {
        return;
    }
    uint64_t word = (uint64_t(floatBitsToUint(depth_of(s.position.z))) << 32) | uint64_t(splat_frame_index + 1u);
    atomicMax(g_splat_nearest[pc.raster.x].w[splat_pixel_index(pixel)], word);
}
