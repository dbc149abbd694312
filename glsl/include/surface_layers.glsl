// The surface-layer tree (dissertation §8.2, Table 8.1; ALGORITHMS.md §4),
// evaluated at a point of the base surface: hat-function and sampled-function
// (§8.3) constraints,
// coverage with noise, depth-first colour blending, displacement feeding
// the next layers' altitude and the normal. Same rules as the CPU reference
// src/surface/layers.rs (`evaluate`); layout as src/surface/gpu_layout.rs.
// A `height_blur` layer's altitude, elevation and slope read a blurred
// height field instead (§8.2.3, snow in furrows; src/surface/blurred_height.rs).
// Needs terrain_detail.glsl (wavelet noise) included first.
#ifndef ALPENGLOW_SURFACE_LAYERS_GLSL
#define ALPENGLOW_SURFACE_LAYERS_GLSL

#include "heap.glsl"
#include "bspline_height.glsl"

struct SurfaceLayer {
    vec4 color_roughness;  // linear colour, roughness B_S (metres)
    vec4 noise;            // c_S, n_S, coverage-noise wavelength, displacement-noise wavelength
    vec4 hats[6];          // constraints (see `constraint`): altitude, elevation, slope, rainfall, radiation, temperature
    uvec4 tree;            // parent (0xffffffff: root), level, blurred height field (sampled), 1: height_blur
};

// The height field's texture (sampled handle), columns × rows and sample
// spacing (metres): what a `height_blur` layer needs besides its blurred field.
struct BaseField {
    uint heights;
    uvec2 dims;
    vec2 spacing;
};

layout(set = 0, binding = 2, std430) readonly buffer SurfaceLayers { SurfaceLayer l[]; } g_surface_layers[];
// The same buffer as floats: the sampled functions' samples follow the layers.
layout(set = 0, binding = 2, std430) readonly buffer SurfaceLayerFloats { float v[]; } g_surface_layer_floats[];

#define MAX_SURFACE_LAYERS 32

// F(a) of a constraint h of the layers buffer `layers` (src/surface/gpu_layout.rs
// `pack_constraint`): w = 0 unused (1); w = 1 a hat (min, max, fuzz); w = 1 + n a
// sampled function of n samples over [min, max] starting at float z of the
// buffer: linear between the bin centres, the end values in the outer
// half-bins, 0 outside [min, max] (src/surface/layers/constraint.rs).
float constraint(uint layers, vec4 h, float a) {
    if (h.w == 0.0) {
        return 1.0;
    }
    if (h.w >= 2.0) {
        if (!(a >= h.x && a <= h.y)) {
            return 0.0;
        }
        uint n = uint(h.w) - 1u;
        float last = float(n - 1u);
        float t = clamp((a - h.x) / (h.y - h.x) * float(n) - 0.5, 0.0, last);
        float i = floor(t);
        float u = t - i;
        uint k = min(uint(i), n - 1u);
        uint first = uint(h.z);
        float lo = g_surface_layer_floats[layers].v[first + k];
        float hi = g_surface_layer_floats[layers].v[first + min(k + 1u, n - 1u)];
        return lo * (1.0 - u) + hi * u;
    }
    if (h.z <= 0.0) {
        return (a >= h.x && a <= h.y) ? 1.0 : 0.0;
    }
    float f1 = (a - (h.x - h.z)) / (2.0 * h.z);
    float f2 = ((h.y + h.z) - a) / (2.0 * h.z);
    return clamp(min(f1, f2), 0.0, 1.0);
}

// Fractional Brownian motion of the wavelet noise tile at wavelength
// `wavelength` (metres): three octaves, lacunarity 2, gain 1/2, scaled to
// about [−1, 1]; `offset` decorrelates layers. Band-limited to the sample
// spacing `footprint` (metres; 0: all octaves): an octave of wavelength λ
// has weight clamp(λ / (2·footprint) − 1, 0, 1), full from four samples per
// wavelength, none at two (Nyquist), so tiles and pixels filter alike.
// Writes the world gradient.
float layer_noise(uint tile, vec2 xy, float wavelength, vec2 offset, float footprint, out vec2 grad) {
    // The tile's noise has a wavelength of about 3 texels.
    float freq = 3.0 / wavelength;
    float value = 0.0;
    float amplitude = 0.87;
    grad = vec2(0.0);
    for (int k = 0; k < 3; ++k) {
        float lambda = wavelength * exp2(-float(k));
        float weight = footprint > 0.0 ? clamp(lambda / (2.0 * footprint) - 1.0, 0.0, 1.0) : 1.0;
        if (weight <= 0.0) {
            break;
        }
        vec2 g;
        value += weight * amplitude * wavelet_noise(tile, xy * freq + offset * float(k + 1), g);
        grad += weight * amplitude * g * freq;
        freq *= 2.0;
        amplitude *= 0.5;
    }
    return value;
}

// The extra input maps (rainfall, radiation, temperature) at uv (0..1 over
// the terrain rectangle): bilinear in R32F textures whose corner samples
// sit on the rectangle's corners; `maps` holds the sampled handles and in w
// bit k when map k is present. An absent map reads −3e38, which every
// constraint rejects (the CPU checks that no layer uses an absent map).
vec3 input_maps(uvec4 maps, vec2 uv) {
    vec3 values = vec3(-3.0e38);
    for (uint k = 0u; k < 3u; ++k) {
        if ((maps.w & (1u << k)) != 0u) {
            uint map = maps[k];
            vec2 size = vec2(textureSize(sampler2D(g_textures[nonuniformEXT(map)], g_samplers[SAMPLER_LINEAR_CLAMP]), 0));
            vec2 at = (clamp(uv, 0.0, 1.0) * (size - 1.0) + 0.5) / size;
            values[k] = textureLod(sampler2D(g_textures[nonuniformEXT(map)], g_samplers[SAMPLER_LINEAR_CLAMP]), at, 0.0).r;
        }
    }
    return values;
}

// What the depth-first walk carries from layer to layer.
struct LayerState {
    float h;            // modified height (metres)
    vec2 extra;         // gradient of the layers' displacement (added to the base gradient)
    float slope;        // slope of the base surface (degrees)
    vec3 color;         // blended linear colour so far
    vec4 coverage;      // C_S of the last layer seen per tree level
    uint dominant;      // the layer with the largest share of the colour so far
    float share;        // its share (src/surface/dominant.rs)
};

// The state before the root: base height h with gradient grad.
LayerState layer_state(float h, vec2 grad) {
    return LayerState(h, vec2(0.0), degrees(atan(length(grad))), vec3(0.0), vec4(1.0), 0u, 0.0);
}

// Layer i of the flat depth-first tree applied at world xy: coverage from
// the constraints (altitude and elevation of the modified height, base slope,
// input maps `maps`), noise and the parent's coverage; colour blend;
// displacement. `range`: the height field's lowest and highest sample;
// `field`: the base height field (read by `height_blur` layers).
void apply_layer(uint layers, uint i, uint tile, vec2 xy, float footprint, vec2 range, vec3 maps, BaseField field,
                 inout LayerState s) {
    uvec4 tree = g_surface_layers[layers].l[i].tree;
    uint level = tree.y;
    vec4 color_roughness = g_surface_layers[layers].l[i].color_roughness;
    vec4 noise = g_surface_layers[layers].l[i].noise;
    float c_s = 1.0;
    if (level > 0u) {
        float altitude = s.h;
        float slope = s.slope;
        if (tree.w != 0u) {
            // The blurred surface plus what the layers before added.
            vec2 base_grad, blurred_grad;
            float base = bspline_height(field.heights, field.dims, field.spacing, xy, base_grad);
            float blurred = bspline_height(tree.z, field.dims, field.spacing, xy, blurred_grad);
            altitude = blurred + (s.h - base);
            slope = degrees(atan(length(blurred_grad)));
        }
        float product =
            constraint(layers, g_surface_layers[layers].l[i].hats[0], altitude) *
            constraint(layers, g_surface_layers[layers].l[i].hats[1], (altitude - range.x) / max(range.y - range.x, 1e-6)) *
            constraint(layers, g_surface_layers[layers].l[i].hats[2], slope) *
            constraint(layers, g_surface_layers[layers].l[i].hats[3], maps.x) *
            constraint(layers, g_surface_layers[layers].l[i].hats[4], maps.y) *
            constraint(layers, g_surface_layers[layers].l[i].hats[5], maps.z);
        // In depth-first order the last layer seen one level up is the parent.
        float parent = s.coverage[min(level - 1u, 3u)];
        if (product > 0.0 && parent > 0.0) {
            vec2 unused;
            float n = noise.y != 0.0
                          ? layer_noise(tile, xy, noise.z, vec2(17.3, 41.9) * float(i + 1u), footprint, unused)
                          : 0.0;
            c_s = clamp((noise.x + noise.y * n) * product, 0.0, 1.0) * parent;
        } else {
            c_s = 0.0;
        }
    }
    s.coverage[min(level, 3u)] = c_s;
    s.color = mix(s.color, color_roughness.rgb, c_s);
    // The dominant layer (src/surface/dominant.rs): every earlier share
    // scales by 1 − C_S, this layer's share is C_S.
    s.share *= 1.0 - c_s;
    if (c_s > s.share) {
        s.dominant = i;
        s.share = c_s;
    }
    if (color_roughness.w > 0.0 && c_s > 0.0) {
        vec2 dg;
        float d = layer_noise(tile, xy, noise.w, vec2(29.1, 7.7) * float(i + 1u), footprint, dg);
        float amplitude = c_s * color_roughness.w;
        s.h += amplitude * d;
        s.extra += amplitude * dg;
    }
}

// The whole tree at world xy of the base surface (height h, gradient grad):
// colour, the displacement gradient in `extra` and the dominant layer.
vec3 evaluate_layers(uint layers, uint count, uint tile, vec2 xy, float footprint, float h, vec2 grad, vec2 range,
                     vec3 maps, BaseField field, out vec2 extra, out uint dominant) {
    LayerState s = layer_state(h, grad);
    for (uint i = 0u; i < count && i < MAX_SURFACE_LAYERS; ++i) {
        apply_layer(layers, i, tile, xy, footprint, range, maps, field, s);
    }
    extra = s.extra;
    dominant = s.dominant;
    return s.color;
}

#endif
