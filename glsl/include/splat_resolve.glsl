// Normalisation and shading of accumulated splats (dissertation §10.2.3
// pass 3, §10.4), shared by points.normalize (three-pass) and
// points.single_pass.resolve, both compute passes: colour = Σw·c / Σw, normal and view depth
// likewise, shaded into radiance and view depth; Σw to the W target; the
// normalised normal (world space, towards the viewer) to the normal AOV.
// The caller writes the ids AOV.
#ifndef ALPENGLOW_SPLAT_RESOLVE_GLSL
#define ALPENGLOW_SPLAT_RESOLVE_GLSL

#include "splat_shading.glsl"

// What a pixel with splats shows.
struct ResolvedSplats {
    vec4 radiance;
    float view_depth;
    float weight;
    vec2 visibility;
    vec4 normal;
};

// The pixel centred at `centre` (pixels) from (Σw·colour, Σw) and
// (Σw·normal, Σw·view depth); Σw > 0.
ResolvedSplats resolve_splats(vec4 cw, vec4 nd, vec2 centre) {
    ResolvedSplats r;
    vec3 albedo = cw.rgb / cw.a;
    float depth = nd.w / cw.a;
    vec3 ray = pixel_ray(centre);
    vec3 position = ray * (depth / -ray.z);
    r.radiance = vec4(shade_splat(albedo, nd.xyz, position, r.visibility), 1.0);
    r.view_depth = depth;
    r.weight = cw.a;
    r.normal = world_normal(nd.xyz, position);
    return r;
}

#ifdef SPLAT_RESOLVE_COMPUTE
// Stores a resolved pixel and its ids into the targets of the push
// constants' outputs and more (splat.glsl).
void store_resolved(ivec2 p, ResolvedSplats r, uvec2 ids) {
    imageStore(g_images_rgba32f[pc.outputs.x], p, r.radiance);
    imageStore(g_images_r32f[pc.outputs.y], p, vec4(r.view_depth));
    imageStore(g_images_r32f[pc.outputs.z], p, vec4(r.weight));
    imageStore(g_images_rg32f[pc.outputs.w], p, vec4(r.visibility, 0.0, 0.0));
    imageStore(g_images_rgba16f[pc.more.x], p, r.normal);
    imageStore(g_uimages_rg32ui[pc.more.y], p, uvec4(ids, 0u, 0u));
}
#endif

#endif
