// The per-pixel state of three-pass EWA splatting in compute (dissertation
// §10.2.3, Table 10.1; src/points/render/compute.rs), as the clear,
// visibility, accumulate and normalize passes see it:
// - nearest: one 64-bit word a pixel, the nearest pushed-back depth's bits
//   (reversed depth, src/view/depth.rs: nearer is greater) << 32 | the
//   winning splat's instance record + 1 (0: the depth buffer's, no splat),
//   raised with atomicMax: the visibility pass's depth test, and a winner
//   that does not depend on the order splats arrive in (ties: the higher record);
// - sums: eight 64-bit integers a pixel, Σw·colour (3), Σw, Σw·normal (3),
//   Σw·(view depth / the nearest word's view depth), each term rounded to
//   SPLAT_SUM_SCALE⁻¹: integer addition commutes, so the sums, and the
//   image, are the same to the byte whatever the order of the fragments.
//   Every term is at most 1 per unit weight (accumulated fragments are no
//   farther than the nearest word), so 2³² keeps 32 fractional bits and
//   still leaves room for 2³⁰ fragments a pixel: the relative error of a
//   pixel whose kernels' weights sum to 10⁻³ stays below 10⁻⁶;
// - last: the highest instance record + 1 of the splats accumulated (the
//   ids where no splat won the visibility pass).
#ifndef ALPENGLOW_SPLAT_COMPUTE_STATE_GLSL
#define ALPENGLOW_SPLAT_COMPUTE_STATE_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "heap.glsl"

layout(set = 0, binding = 2, std430) buffer SplatNearest { uint64_t w[]; } g_splat_nearest[];
layout(set = 0, binding = 2, std430) buffer SplatSums { int64_t s[]; } g_splat_sums[];
layout(set = 0, binding = 2, std430) buffer SplatLast { uint r[]; } g_splat_last[];

// Sums per pixel, and the fixed-point scale of their terms (2³²).
#define SPLAT_SUMS 8u
const float SPLAT_SUM_SCALE = 4294967296.0;

// Adds a fragment of weight `w` (colour, normal, view depth relative to
// the nearest word's) to pixel `p`'s sums in buffer `sums` and raises its
// last record (buffer `last`) to `record` + 1.
void splat_accumulate(uvec2 buffers, uint p, float w, vec3 color, vec3 normal, float relative_depth, uint record) {
    float terms[SPLAT_SUMS] = float[](color.r, color.g, color.b, 1.0, normal.x, normal.y, normal.z, relative_depth);
    for (uint k = 0u; k < SPLAT_SUMS; ++k) {
        atomicAdd(g_splat_sums[buffers.x].s[p * SPLAT_SUMS + k], int64_t(round(terms[k] * w * SPLAT_SUM_SCALE)));
    }
    atomicMax(g_splat_last[buffers.y].r[p], record + 1u);
}

// The nearest depth (reversed: nearer is greater) of pixel `p` in buffer `nearest`.
float splat_nearest_depth(uint nearest, uint p) {
    return uintBitsToFloat(uint(g_splat_nearest[nearest].w[p] >> 32));
}

// The view depth −z of depth-buffer value `depth` with the point frame's
// depth row `row` = (P22, P32) (depth = (P22·z + P32)/−z, splat.glsl's
// depth_of): −z = P32 / (depth + P22).
float splat_view_depth(float depth, vec2 row) {
    return row.y / max(depth + row.x, 1e-30);
}

// Raises pixel `p`'s nearest word to (`depth`, `record` + 1).
void splat_raise_nearest(uint nearest, uint p, float depth, uint record) {
    atomicMax(g_splat_nearest[nearest].w[p], (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(record + 1u));
}

#endif
