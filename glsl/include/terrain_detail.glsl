// Procedural terrain detail shared by terrain.warp (geometry) and
// terrain.draw (bump mapping): band-limited wavelet noise octaves split
// between vertex displacement and per-pixel shading at the split octave
// (dissertation §7.4.3, "Procedural Detail"; ALGORITHMS.md §3 item 6).
//
// Octave k ≥ 1 evaluates the wavelet noise tile at world xy · 2^k / d0
// (tile texels; d0 = sketch-atlas spacing), so its wavelength is about
// 3·d0 / 2^k: octave 1 starts just above what the atlas itself can carry.
// Its amplitude is `amp · d0 · 2^(-k·H)`.
//
// Octave weights: the "range up to o" has weight clamp(o − (k − 1), 0, 1)
// for octave k: octaves ≤ ⌊o⌋ fully, octave ⌊o⌋+1 by the fraction of o.
// The geometry gets the range up to the split octave o_split; shading gets
// the range up to the pixel footprint minus the geometry's share, so the
// blended octave is shared exactly (weights add to one).
#ifndef ALPENGLOW_TERRAIN_DETAIL_GLSL
#define ALPENGLOW_TERRAIN_DETAIL_GLSL

// Must match src/terrain/geometry_image.rs and its CPU twin src/terrain/ground.rs.
const float SPLIT_BIAS = 0.5;    // conservative shift of detail to shading (octaves)
const int MAX_DETAIL_OCTAVES = 8;
const int NOISE_TILE = 128;

// Cook & DeRose wavelet noise (2005), quadratic B-spline evaluation of the
// periodic tile at p (tile texels); returns the value and writes d/dp.
// Convention of src/surface/wavelet_noise.rs: mid = ceil(p − 0.5),
// t = mid − (p − 0.5), w0 = t²/2, w2 = (1 − t)²/2, w1 = 1 − w0 − w2 for taps
// mid − 1, mid, mid + 1 (periodic).
float wavelet_noise(uint tile, vec2 p, out vec2 grad) {
    vec2 mid = ceil(p - 0.5);
    vec2 t = mid - (p - 0.5);
    vec2 w0 = 0.5 * t * t;
    vec2 w2 = 0.5 * (1.0 - t) * (1.0 - t);
    vec2 w1 = 1.0 - w0 - w2;
    // d/dp: dt/dp = −1.
    vec2 d0 = -t;
    vec2 d2 = 1.0 - t;
    vec2 d1 = -d0 - d2;
    vec2 w[3] = vec2[3](w0, w1, w2);
    vec2 dw[3] = vec2[3](d0, d1, d2);
    ivec2 base = ivec2(mid) - 1;
    float value = 0.0;
    grad = vec2(0.0);
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {
            ivec2 q = (base + ivec2(i, j)) & (NOISE_TILE - 1);
            float n = texelFetch(sampler2D(g_textures[tile], g_samplers[SAMPLER_NEAREST_REPEAT]), q, 0).r;
            value += w[i].x * w[j].y * n;
            grad += vec2(dw[i].x * w[j].y, w[i].x * dw[j].y) * n;
        }
    }
    return value;
}

// Weight of octave k in the range up to octave o.
float octave_weight(float o, int k) {
    return clamp(o - float(k - 1), 0.0, 1.0);
}

// Sum of the detail octaves weighted by w(k) = weight(o_hi, k) − weight(o_lo, k):
// height (metres) and its world-space gradient.
float detail_octaves(uint tile, vec2 xy, float d0, float amp, float H, float o_lo, float o_hi, out vec2 grad) {
    float h = 0.0;
    grad = vec2(0.0);
    int last = min(int(ceil(o_hi)), MAX_DETAIL_OCTAVES);
    for (int k = 1; k <= last; ++k) {
        float w = octave_weight(o_hi, k) - octave_weight(o_lo, k);
        if (w <= 0.0) {
            continue;
        }
        float freq = exp2(float(k)) / d0;
        // A per-octave shift decorrelates the octaves' lattices.
        vec2 p = xy * freq + vec2(37.13, 11.71) * float(k);
        vec2 g;
        float n = wavelet_noise(tile, p, g);
        float a = w * amp * d0 * exp2(-float(k) * H);
        h += a * n;
        grad += a * g * freq;
    }
    return h;
}

#endif
