#version 460
// points.normalize (dissertation §10.2.3, Table 10.1 pass 3): a full-screen
// pass; per pixel colour = Σw·c / Σw, normal and view depth likewise, then
// shading into the radiance and view-depth targets. Σw = 0 (no splat) keeps
// what the terrain and sky passes wrote. Σw goes to the W target (cleared to 0),
// the normalised accumulated normal (world space, towards the viewer) to the
// normal AOV, and the ids (class, instance) of the surfel that won the
// visibility pass, or where none did (its pushed-back depth lost against the
// terrain, the surface is in front of it) of the last surfel accumulated:
// one surfel's ids, never a blend.
#include "../include/splat_shading.glsl"

// Push constants (the splat passes' block, splat.glsl):
//   handles = (accumulated colour+w, point frame, accumulated normal+depth (sampled), unused),
//   mode.xy = ids of the nearest surfel, ids of the last accumulated surfel (sampled, RG32UI).
layout(location = 0) out vec4 out_radiance;
layout(location = 1) out float out_view_depth;
layout(location = 2) out float out_weight;
layout(location = 3) out vec2 out_visibility;
layout(location = 4) out vec4 out_normal;
layout(location = 5) out uvec2 out_ids;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 cw = texelFetch(sampler2D(g_textures[pc.handles.x], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0);
    if (!(cw.a > 0.0)) {
        discard;
    }
    vec4 nd = texelFetch(sampler2D(g_textures[pc.handles.z], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0);
    vec3 albedo = cw.rgb / cw.a;
    float depth = nd.w / cw.a;
    vec3 ray = pixel_ray(gl_FragCoord.xy);
    vec3 position = ray * (depth / -ray.z);
    out_radiance = vec4(shade_splat(albedo, nd.xyz, position, out_visibility), 1.0);
    out_view_depth = depth;
    out_weight = cw.a;
    out_normal = world_normal(nd.xyz, position);
    uvec2 nearest = texelFetch(usampler2D(g_utextures[pc.mode.x], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0).xy;
    uvec2 last = texelFetch(usampler2D(g_utextures[pc.mode.y], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0).xy;
    out_ids = nearest.x != 0u ? nearest : last;
}
