// Normalisation and shading of accumulated splats (dissertation §10.2.3
// pass 3, §10.4), shared by points.normalize (three-pass, a compute pass)
// and points.single_pass.resolve: colour = Σw·c / Σw, normal and view depth
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

#endif
