// The per-pixel state of three-pass EWA splatting in compute (dissertation
// §10.2.3, Table 10.1; src/points/render/compute.rs), as the clear,
// visibility, accumulate and normalize passes see it:
// - nearest: one 64-bit word a pixel, the nearest pushed-back depth's bits
//   (reversed depth, src/view/depth.rs: nearer is greater) << 32 | the
//   winning splat's instance record + 1 (0: the depth buffer's, no splat),
//   raised with atomicMax: the visibility pass's depth test, and a winner
//   that does not depend on the order splats arrive in (ties: the higher record);
// - sums: eight 64-bit integers a pixel, Σw·colour (3), Σw, Σw·normal (3),
//   Σw·view depth, each term rounded to SPLAT_SUM_SCALE⁻¹: integer addition
//   commutes, so the sums, and the image, are the same to the byte whatever
//   the order of the fragments;
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

// Sums per pixel, and the fixed-point scale of their terms (2²⁴: weights
// and colours ≤ 1 keep 24 bits; a view depth of 10⁶ m still leaves room
// for 10⁵ fragments a pixel in 63 bits).
#define SPLAT_SUMS 8u
const float SPLAT_SUM_SCALE = 16777216.0;

#endif
