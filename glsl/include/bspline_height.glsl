// The height field as a uniform cubic B-spline surface (dissertation §7.4
// "sketch atlas", §8.2 root upsampling; ALGORITHMS.md §3 item 5 and §4):
// height and world gradient at world xy from the R32F height texture.
// Same convention as src/surface/bspline.rs.
#ifndef ALPENGLOW_BSPLINE_HEIGHT_GLSL
#define ALPENGLOW_BSPLINE_HEIGHT_GLSL

#include "heap.glsl"

// Uniform cubic B-spline weights and their derivatives for fraction t.
void bspline(float t, out vec4 w, out vec4 dw) {
    float t2 = t * t;
    float t3 = t2 * t;
    w = vec4((1.0 - t) * (1.0 - t) * (1.0 - t), 3.0 * t3 - 6.0 * t2 + 4.0, -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) / 6.0;
    dw = vec4(-(1.0 - t) * (1.0 - t), 3.0 * t2 - 4.0 * t, -3.0 * t2 + 2.0 * t + 1.0, t2) * 0.5;
}

// Height and gradient (per sample) at sample coordinates g (clamped to the
// `dims` columns × rows); sample q is texel q mod `wrap` of the texture
// `heights` (a toroidal detail window, detail_window.glsl; the atlas:
// wrap ≥ both dims, no wrap).
float bspline_samples(uint heights, uvec2 dims, uint wrap, vec2 g, out vec2 grad) {
    g = clamp(g, vec2(0.0), vec2(dims - 1u));
    vec2 base = floor(g);
    vec2 t = g - base;
    vec4 wx, wy, dx, dy;
    bspline(t.x, wx, dx);
    bspline(t.y, wy, dy);
    ivec2 b = ivec2(base) - 1;
    float h = 0.0;
    grad = vec2(0.0);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            ivec2 q = clamp(b + ivec2(i, j), ivec2(0), ivec2(dims) - 1) % int(wrap);
            float v = texelFetch(sampler2D(g_textures[heights], g_samplers[SAMPLER_NEAREST_CLAMP]), q, 0).r;
            h += wx[i] * wy[j] * v;
            grad += vec2(dx[i] * wy[j], wx[i] * dy[j]) * v;
        }
    }
    return h;
}

// Height and world gradient at world xy; `heights` the texture handle,
// `dims` columns × rows, `spacing` metres between samples.
float bspline_height(uint heights, uvec2 dims, vec2 spacing, vec2 xy, out vec2 grad) {
    float h = bspline_samples(heights, dims, max(dims.x, dims.y), xy / spacing, grad);
    grad /= spacing;
    return h;
}

#endif
