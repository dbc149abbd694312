// Sky light on the terrain (§9.3–9.5) from the per-texel sky-light map the
// frame's lighting.sky_light pass wrote (SH transfer, AO with bent normals,
// sky patches, unoccluded; src/lighting/sky_light) or the Monte Carlo
// reference: rgb = outgoing radiance per unit albedo, a = sky visibility.
// The map is per height-field texel (its normal from the field's central
// differences); the shading normal is not used.
#ifndef ALPENGLOW_SKY_LIGHT_GLSL
#define ALPENGLOW_SKY_LIGHT_GLSL

#include "lighting.glsl"
#include "sky.glsl"

// Unoccluded sky light per unit albedo for normal `n`: E(n)/π by a fixed
// cosine-weighted quadrature of the sky model (the normal and two rings of
// four directions at 30° and 60° from it; deterministic). Used where no
// per-texel map exists (scenes without terrain) and, scaled by the
// terrain's sky visibility there, for point objects (§9.5: AO per surfel).
vec3 unoccluded_sky_light(uint lighting, vec3 n) {
    vec3 t = normalize(abs(n.z) < 0.9 ? cross(n, vec3(0.0, 0.0, 1.0)) : cross(n, vec3(1.0, 0.0, 0.0)));
    vec3 b = cross(n, t);
    // Cosine-weighted: weight ∝ cos θ · sin θ over rings at θ = 0, 30°, 60°.
    vec3 sum = sky_radiance(lighting, n) * 0.1;
    float total = 0.1;
    for (int ring = 1; ring <= 2; ++ring) {
        float theta = float(ring) * 0.5235988;
        float w = cos(theta) * sin(theta);
        for (int k = 0; k < 4; ++k) {
            float phi = float(k) * 1.5707963 + float(ring) * 0.7853982;
            vec3 d = cos(theta) * n + sin(theta) * (cos(phi) * t + sin(phi) * b);
            sum += sky_radiance(lighting, d) * w;
            total += w;
        }
    }
    return sum / total;
}

// rgb: outgoing radiance per unit albedo from sky light at world point
// `world` (bilinear between the texels around world.xy); a: sky visibility
// (1 = open sky). `point_object`: a point object's surface, lit by the open
// sky for its own normal and occluded as the terrain under it is.
vec4 sky_light(uint lighting, vec3 world, vec3 normal, bool point_object) {
    vec4 field = g_lighting[lighting].f.field;
    uint map = g_lighting[lighting].f.maps.x;
    if (map == 0u) {
        return vec4(unoccluded_sky_light(lighting, normal), 1.0);
    }
    vec2 texels = max(field.zw, vec2(1.0));
    vec2 uv = (world.xy / max(field.xy, vec2(1e-6)) * field.zw + 0.5) / (texels + 1.0);
    vec4 terrain = textureLod(sampler2D(g_textures[nonuniformEXT(map)], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0);
    if (point_object) {
        return vec4(unoccluded_sky_light(lighting, normal) * terrain.a, terrain.a);
    }
    return terrain;
}

#endif
