#version 460
// points.normalize (dissertation §10.2.3, Table 10.1 pass 3): a compute
// pass over the view's pixels; per pixel the accumulated sums are
// normalised and shaded (glsl/include/splat_resolve.glsl). Σw = 0 (no
// splat) keeps what the terrain and sky passes wrote, but W, which is 0
// there. The ids (class, instance) are those of the surfel that won the
// visibility pass, or where none did (its pushed-back depth lost against
// the terrain, the surface is in front of it) of the last surfel
// accumulated: one surfel's ids, never a blend.
#define SPLAT_RESOLVE_COMPUTE
#include "../include/splat_resolve.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (accumulated colour+w, point frame, accumulated normal+depth (sampled), unused),
//   mode.xy = ids of the nearest surfel, ids of the last accumulated surfel (sampled, RG32UI),
//   outputs, more = the targets written.

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.more.zw))) {
        return;
    }
    vec4 cw = texelFetch(sampler2D(g_textures[pc.handles.x], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0);
    if (!(cw.a > 0.0)) {
        imageStore(g_images_r32f[pc.outputs.z], p, vec4(0.0));
        return;
    }
    vec4 nd = texelFetch(sampler2D(g_textures[pc.handles.z], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0);
    ResolvedSplats r = resolve_splats(cw, nd, vec2(p) + 0.5);
    uvec2 nearest = texelFetch(usampler2D(g_utextures[pc.mode.x], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0).xy;
    uvec2 last = texelFetch(usampler2D(g_utextures[pc.mode.y], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0).xy;
    store_resolved(p, r, nearest.x != 0u ? nearest : last);
}
