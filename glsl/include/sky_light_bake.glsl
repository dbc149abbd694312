// Shared by the sky-light bake passes (horizon tracing, transfer, bounces;
// §9.3–9.5, src/lighting/sky_light/bake.rs): the height field and the
// per-texel buffers, bound through the heap.
#ifndef ALPENGLOW_SKY_LIGHT_BAKE_GLSL
#define ALPENGLOW_SKY_LIGHT_BAKE_GLSL

#include "heap.glsl"

const float BAKE_PI = 3.14159265358979;

layout(set = 0, binding = 2, std430) readonly buffer BakeHeights { float h[]; } g_bake_heights[];
layout(set = 0, binding = 2, std430) buffer BakeFloats { float v[]; } g_bake_floats[];
layout(set = 0, binding = 2, std430) buffer BakeUints { uint v[]; } g_bake_uints[];

// Height of sample (c, r), clamped to the grid.
float bake_height(uint heights, ivec2 grid, ivec2 p) {
    p = clamp(p, ivec2(0), grid - 1);
    return g_bake_heights[heights].h[p.y * grid.x + p.x];
}

// Bilinear height at continuous texel coordinates t.
float bake_height_bilinear(uint heights, ivec2 grid, vec2 t) {
    t = clamp(t, vec2(0.0), vec2(grid - 1));
    ivec2 i = min(ivec2(floor(t)), grid - 2);
    vec2 f = t - vec2(i);
    float h00 = bake_height(heights, grid, i);
    float h10 = bake_height(heights, grid, i + ivec2(1, 0));
    float h01 = bake_height(heights, grid, i + ivec2(0, 1));
    float h11 = bake_height(heights, grid, i + ivec2(1, 1));
    return mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
}

// Unit normal at sample p from central differences (one-sided at the edges).
vec3 bake_normal(uint heights, ivec2 grid, ivec2 p, vec2 spacing) {
    ivec2 lo = max(p - 1, ivec2(0));
    ivec2 hi = min(p + 1, grid - 1);
    float dhdx = (bake_height(heights, grid, ivec2(hi.x, p.y)) - bake_height(heights, grid, ivec2(lo.x, p.y))) /
                 (float(hi.x - lo.x) * spacing.x);
    float dhdy = (bake_height(heights, grid, ivec2(p.x, hi.y)) - bake_height(heights, grid, ivec2(p.x, lo.y))) /
                 (float(hi.y - lo.y) * spacing.y);
    return normalize(vec3(-dhdx, -dhdy, 1.0));
}

// ∫ sqrt(1 − z²) dz (antiderivative).
float bake_circle(float z) {
    z = clamp(z, -1.0, 1.0);
    return 0.5 * (z * sqrt(max(1.0 - z * z, 0.0)) + asin(z));
}

// ∫_{z1}^{z2} max(0, n·ω) dz along one azimuth, for z1 ≥ the terminator:
// n·ω = n_z z + n_t sqrt(1 − z²).
float bake_cosine_integral(float n_z, float n_t, float z1, float z2) {
    return n_z * 0.5 * (z2 * z2 - z1 * z1) + n_t * (bake_circle(z2) - bake_circle(z1));
}

// Lowest z with n·ω ≥ 0 along an azimuth (n_z > 0 for a height field).
float bake_terminator(float n_z, float n_t) {
    return -n_t / max(length(vec2(n_z, n_t)), 1e-12);
}

#endif
