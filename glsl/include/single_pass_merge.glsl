// The fuzzy-depth merge of single-pass splatting (dissertation §10.4),
// interlock backend (glsl/points/single_pass_interlock.frag): the pixel state
// buffers, the fragment of a splat at a pixel, and the text's operator done
// inside the pixel-ordered critical section. (The compute backend merges
// per tile in registers: glsl/points/single_pass_tile.comp.)
#ifndef ALPENGLOW_SINGLE_PASS_MERGE_GLSL
#define ALPENGLOW_SINGLE_PASS_MERGE_GLSL

#ifndef SPLAT_SINGLE_PASS
#error "define SPLAT_SINGLE_PASS before the first include of splat.glsl"
#endif
#include "splat_setup.glsl"
#include "single_pass_state.glsl"

// Per pixel: a word unused by the interlock (0) and z_d's bits.
layout(set = 0, binding = 2, std430) coherent buffer PixelWords32 { uint w[]; } g_pixel_words32[];
layout(set = 0, binding = 2, std430) coherent buffer PixelSumsBuffer { PixelSums p[]; } g_pixel_sums[];

// A splat's fragment: the weighted sums it adds, its ids, its pixel, its
// distance z along the view ray and its tolerance z_f = ε·r_k.
struct SplatFragment {
    vec4 color_weight;
    vec4 normal_depth;
    uvec4 ids;
    uint pixel;
    float z;
    float zf;
};

// The fragment of splat `v` sampled as `s` at `pixel`; false when the depth
// buffer (terrain, hybrid triangles) is nearer (the three-pass
// accumulation's test; reversed depth, src/view/depth.rs: nearer is greater).
bool single_pass_fragment(SplatSetup v, SplatSample s, uvec2 pixel, out SplatFragment frag) {
    uint depth_buffer = pc.single.z;
    if (depth_buffer != NO_HANDLE) {
        float stored = texelFetch(sampler2D(g_textures[depth_buffer], g_samplers[SAMPLER_NEAREST_CLAMP]),
                                  ivec2(pixel), 0).r;
        if (depth_of(s.position.z) < stored) {
            return false;
        }
    }
    uint f = pc.handles.y;
    float w = s.weight;
    frag.color_weight = vec4(v.color.rgb * w, w);
    frag.normal_depth = vec4(v.normal.xyz * w, -s.position.z * w);
    frag.ids = uvec4(instance_ids(), 0u, 0u);
    frag.pixel = pixel.y * uint(g_point_frame[f].viewport.x) + pixel.x;
    frag.z = length(s.position);
    frag.zf = g_point_frame[f].depth.z * v.centre.z;
    return true;
}

// The text's operator on the pixel's sums, with z_d = `zd` < z + z_f (the
// caller holds the pixel): replaces when nearer than z_d − z_f, else adds;
// returns the new z_d.
float merge_locked(SplatFragment frag, float zd) {
    uint sums = pc.single.y;
    if (frag.z < zd - frag.zf) {
        g_pixel_sums[sums].p[frag.pixel].color_weight = frag.color_weight;
        g_pixel_sums[sums].p[frag.pixel].normal_depth = frag.normal_depth;
        g_pixel_sums[sums].p[frag.pixel].ids = frag.ids;
        return frag.z;
    }
    g_pixel_sums[sums].p[frag.pixel].color_weight += frag.color_weight;
    g_pixel_sums[sums].p[frag.pixel].normal_depth += frag.normal_depth;
    return zd;
}

#endif
