#version 460
// points.accumulate on the compute path (dissertation §10.2.3, Table 10.1
// pass 2): fragments at or in front of the pixel's nearest pushed-back depth
// (the hardware pass's ≤ test without depth writes) add w·(colour, 1) and
// w·(normal, view depth) to the pixel's fixed-point sums with 64-bit integer
// atomics (glsl/include/splat_compute_state.glsl): order-independent, so the
// frame is the same to the byte on every run.
#include "../include/splat_compute.glsl"

void add(uint base, uint k, float value) {
    atomicAdd(g_splat_sums[pc.raster.y].s[base + k], int64_t(round(value * SPLAT_SUM_SCALE)));
}

void splat_pixel(SplatSetup v, uvec2 pixel) {
    SplatSample s;
    if (!splat_sample_at(vec2(pixel) + 0.5, v, s)) {
        return;
    }
    uint p = splat_pixel_index(pixel);
    float nearest = uintBitsToFloat(uint(g_splat_nearest[pc.raster.x].w[p] >> 32));
    if (depth_of(s.position.z) < nearest) {
        return;
    }
    float w = s.weight;
    uint base = p * SPLAT_SUMS;
    add(base, 0u, v.color.r * w);
    add(base, 1u, v.color.g * w);
    add(base, 2u, v.color.b * w);
    add(base, 3u, w);
    add(base, 4u, v.normal.x * w);
    add(base, 5u, v.normal.y * w);
    add(base, 6u, v.normal.z * w);
    add(base, 7u, -s.position.z * w);
    atomicMax(g_splat_last[pc.raster.z].r[p], splat_record + 1u);
}
