// Normalisation and shading of accumulated splats (dissertation §10.2.3
// pass 3, §10.4), shared by points.normalize (three-pass) and
// points.single_pass.resolve: colour = Σw·c / Σw, normal and view depth
// likewise, shaded into radiance and view depth; Σw to the W target; the
// normalised normal (world space, towards the viewer) to the normal AOV.
// The caller writes the ids AOV.
#ifndef ALPENGLOW_SPLAT_RESOLVE_GLSL
#define ALPENGLOW_SPLAT_RESOLVE_GLSL

#include "splat_shading.glsl"

layout(location = 0) out vec4 out_radiance;
layout(location = 1) out float out_view_depth;
layout(location = 2) out float out_weight;
layout(location = 3) out vec2 out_visibility;
layout(location = 4) out vec4 out_normal;
layout(location = 5) out uvec2 out_ids;

// Writes the outputs but the ids from (Σw·colour, Σw) and (Σw·normal,
// Σw·view depth); Σw > 0.
void resolve_splats(vec4 cw, vec4 nd) {
    vec3 albedo = cw.rgb / cw.a;
    float depth = nd.w / cw.a;
    vec3 ray = pixel_ray(gl_FragCoord.xy);
    vec3 position = ray * (depth / -ray.z);
    out_radiance = vec4(shade_splat(albedo, nd.xyz, position, out_visibility), 1.0);
    out_view_depth = depth;
    out_weight = cw.a;
    out_normal = world_normal(nd.xyz, position);
}

#endif
