// Shared by the passes of the neighbourhood search of height-field synthesis
// (§7.3; ALGORITHMS.md §2; src/synthesis/gpu.rs, whose CPU twin is
// src/synthesis/search.rs): the buffers, the push constants, the choice hash
// and the order-preserving key of a float.
#ifndef ALPENGLOW_SYNTHESIS_SEARCH_GLSL
#define ALPENGLOW_SYNTHESIS_SEARCH_GLSL

#include "heap.glsl"

// Exemplar texels (h, ∂h/∂x, ∂h/∂y, 0), row-major.
layout(set = 0, binding = 2, std430) readonly buffer SynthesisTexels { vec4 t[]; } g_synthesis_texels[];
// Query taps (h, hx, hy, w), n² per query in tap order.
layout(set = 0, binding = 2, std430) readonly buffer SynthesisTaps { vec4 t[]; } g_synthesis_taps[];
// Candidate centres, query pixels.
layout(set = 0, binding = 2, std430) readonly buffer SynthesisUints { uint u[]; } g_synthesis_uints[];
// s(c) per (query, candidate): query-major.
layout(set = 0, binding = 2, std430) buffer SynthesisSums { float s[]; } g_synthesis_sums[];
// Per query: x key of the best s, y smallest accepted hash, z smallest
// candidate with that hash, w unused.
layout(set = 0, binding = 2, std430) buffer SynthesisResults { uvec4 r[]; } g_synthesis_results[];

layout(push_constant) uniform Push {
    uvec4 inputs;   // handles: texels, candidate centres, taps, pixels
    uvec4 outputs;  // handles: sums, results, readback; unused
    uvec4 sizes;    // queries in this batch, candidates, window n, exemplar width
    uvec4 rule;     // seed, bits of λ, bits of (1 + ε) (rounded as on the CPU), unused
} pc;

// Nothing accepted yet / no candidate picked.
const uint SYNTHESIS_NONE = 0xffffffffu;

// lowbias32 (Chris Wellons' integer hash), as `search::lowbias32`.
uint lowbias32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// The hash that orders the accepted candidates of a pixel (`search::choice_hash`).
uint choice_hash(uint seed, uint pixel, uint candidate) {
    return lowbias32(lowbias32(lowbias32(seed) ^ pixel) ^ candidate);
}

// A uint whose order is the floats' order (NaN above everything, so a
// minimum ignores it as `f32::min` does).
uint float_key(float f) {
    if (isnan(f)) {
        return 0xffffffffu;
    }
    uint b = floatBitsToUint(f);
    return (b & 0x80000000u) != 0u ? ~b : (b | 0x80000000u);
}

// The float of a key (`float_key`'s inverse).
float key_float(uint k) {
    return uintBitsToFloat((k & 0x80000000u) != 0u ? (k & 0x7fffffffu) : ~k);
}

// The key a per-query minimum starts from: +∞ (every s is below or equal).
const uint SYNTHESIS_KEY_INFINITY = 0xff800000u;

// The tolerance of query q: a candidate is accepted when s(c) ≤ (1 + ε)·best,
// the product rounded once as on the CPU.
float synthesis_threshold(uint results_handle, uint q) {
    float best = key_float(g_synthesis_results[results_handle].r[q].x);
    precise float threshold = uintBitsToFloat(pc.rule.z) * best;
    return threshold;
}

#endif
