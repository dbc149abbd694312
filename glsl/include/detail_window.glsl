// The detail window over the resident sketch atlas (issue 31 item 1,
// §7.4.4; src/terrain/detail/mod.rs, whose DetailWindow::height is the CPU
// twin): where the window's active rectangle holds the B-spline's taps,
// heights blend from the resident level to the window's finer level over a
// band (a smoothstep per side, their product), gradients with the blend's
// exact derivative. The image is toroidal: level sample (c, r) at texel
// (c mod side, r mod side).
#ifndef ALPENGLOW_DETAIL_WINDOW_GLSL
#define ALPENGLOW_DETAIL_WINDOW_GLSL

#include "bspline_height.glsl"

struct DetailWindow {
    uvec4 grid;     // sampled handle, side, level columns, level rows
    vec4 valid;     // B-spline taps inside the active rectangle: lo x, lo y, hi x, hi y (level samples)
    vec4 spacing;   // level spacing x, y (m), blend band (samples), on (1) / off (0)
};

// smoothstep(0, band, d) and its derivative in d.
vec2 detail_smooth(float d, float band) {
    float t = clamp(d / band, 0.0, 1.0);
    float dt = (d > 0.0 && d < band) ? 1.0 / band : 0.0;
    return vec2(t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t) * dt);
}

// The window's B-spline at level sample coordinates g.
float detail_bspline(DetailWindow w, vec2 g, out vec2 grad) {
    float h = bspline_samples(w.grid.x, w.grid.zw, w.grid.y, g, grad);
    grad /= w.spacing.xy;
    return h;
}

// Height at world xy: `coarse` (with gradient `coarse_grad`) from the
// resident atlas, blended into the window where it holds the point;
// `weight` the window's share (0 to 1).
float detail_height(DetailWindow w, vec2 xy, float coarse, vec2 coarse_grad, out vec2 grad, out float weight) {
    grad = coarse_grad;
    weight = 0.0;
    if (w.spacing.w < 0.5) {
        return coarse;
    }
    vec2 g = xy / w.spacing.xy;
    float band = w.spacing.z;
    vec2 x0 = detail_smooth(g.x - w.valid.x, band), x1 = detail_smooth(w.valid.z - g.x, band);
    vec2 y0 = detail_smooth(g.y - w.valid.y, band), y1 = detail_smooth(w.valid.w - g.y, band);
    float wx = x0.x * x1.x, wy = y0.x * y1.x;
    weight = wx * wy;
    if (weight <= 0.0) {
        return coarse;
    }
    vec2 fine_grad;
    float fine = detail_bspline(w, g, fine_grad);
    vec2 dw = vec2((x0.y * x1.x - x0.x * x1.y) * wy / w.spacing.x, wx * (y0.y * y1.x - y0.x * y1.y) / w.spacing.y);
    grad = mix(coarse_grad, fine_grad, weight) + (fine - coarse) * dw;
    return mix(coarse, fine, weight);
}

// The ground terrain.warp draws at world xy before its procedural octaves:
// the resident sketch atlas's B-spline (sampled handle `atlas`, `dims`
// samples `spacing` metres apart) blended into the window's; `weight` the
// window's share. Texturing reads the same surface (texturing.upsample,
// direct texturing), so the layers' altitude and slope follow what is drawn.
float detail_surface(DetailWindow w, uint atlas, uvec2 dims, vec2 spacing, vec2 xy, out vec2 grad, out float weight) {
    vec2 coarse_grad;
    float coarse = bspline_height(atlas, dims, spacing, xy, coarse_grad);
    return detail_height(w, xy, coarse, coarse_grad, grad, weight);
}

// The procedural octave from which detail adds where the window has
// weight `weight` (d0: the resident spacing): its samples replace the
// octaves between d0 and their own spacing.
float detail_window_octave(DetailWindow w, float weight, float d0) {
    return weight > 0.0 ? weight * max(log2(d0 / min(w.spacing.x, w.spacing.y)), 0.0) : 0.0;
}

#endif
