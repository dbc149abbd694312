// Sun visibility (§9.5): cascaded shadow maps with percentage-closer
// filtering, or the horizon maps of the height field, by models.y.
// The atlas, cascade matrices and texel sizes come from LightingFrame
// (src/lighting/shadows/cascades.rs fills them): cascade i owns quadrant
// (i % 2, i / 2) of one D32 image; depth 0 is nearest the sun.
#ifndef ALPENGLOW_SHADOWS_GLSL
#define ALPENGLOW_SHADOWS_GLSL

#include "lighting.glsl"
#include "horizon.glsl"

// Fraction of the cascade's depth range over which it blends into the next.
const float SHADOW_BLEND_BAND = 0.1;

// Filtered visibility of world point `p` in cascade `i`: a separable tent of
// half-width R + 1 texels (R = PCF radius) over the (2R + 2)² texels around
// p's position, weights depending continuously on the sub-texel position
// (bilinear for R = 0, 5×5-like tent for R = 2); deterministic.
float shadow_cascade_pcf(uint lighting, uint i, vec3 p) {
    uvec4 sh = g_lighting[lighting].f.shadows;
    vec4 clip = g_lighting[lighting].f.cascade_view_proj[i] * vec4(p, 1.0);
    float size = float(sh.z);
    int radius = int(sh.w);
    float extent = float(radius) + 1.0;
    vec2 tc = (clip.xy * 0.5 + 0.5) * size - 0.5;
    vec2 base = floor(tc);
    vec2 f = tc - base;
    int quadrant = int(sh.z / 2u);
    ivec2 q0 = ivec2(int(i % 2u), int(i / 2u)) * quadrant;
    ivec2 q1 = q0 + ivec2(quadrant - 1);
    float reference = clip.z;
    float lit = 0.0;
    float total = 0.0;
    for (int y = -radius; y <= radius + 1; ++y) {
        float wy = max(extent - abs(float(y) - f.y), 0.0);
        for (int x = -radius; x <= radius + 1; ++x) {
            float w = wy * max(extent - abs(float(x) - f.x), 0.0);
            ivec2 texel = clamp(ivec2(base) + ivec2(x, y), q0, q1);
            // sh.x is the view's atlas, uniform over the dispatch: no
            // nonuniformEXT (lavapipe 25.0's compute shaders crash on a
            // non-uniform texelFetch of a depth image).
            float depth = texelFetch(sampler2D(g_textures[sh.x], g_samplers[SAMPLER_NEAREST_CLAMP]),
                                     texel, 0).r;
            lit += reference <= depth ? w : 0.0;
            total += w;
        }
    }
    return total > 0.0 ? lit / total : 1.0;
}

// Soft sun (§9.5: "efficient shadow algorithms and approximations for simple
// soft shadows"; percentage-closer soft shadows): a blocker at distance d
// (m, along the sun) hides the part of the sun's disc (angular radius r)
// within d·tan r of the ray, so the visible fraction is the shadow test
// filtered by a uniform disc of radius ρ = d·tan r. A blocker search first
// (SOFT_SEARCH² taps over the widest reach, receiver depth × tan r, keeping
// only blockers whose own reach d·tan r covers the tap's offset) gives the
// mean blocker distance, then a disc of SOFT_TAPS taps per radius (each a
// bilinear shadow test) filters with ρ, never below the PCF tent's R + 1
// texels nor above SOFT_MAX_TEXELS. Taps compare against the receiver's
// plane (receiver-plane depth bias from the normal). Deterministic.
const int SOFT_SEARCH = 2;            // (2·2 + 1)² search taps
const int SOFT_TAPS = 3;              // (2·3 + 1)² filter taps, a disc of radius 3.5 tap steps
const float SOFT_MAX_TEXELS = 24.0;

float shadow_atlas_depth(uint atlas, ivec2 texel, ivec2 q0, ivec2 q1) {
    return texelFetch(sampler2D(g_textures[atlas], g_samplers[SAMPLER_NEAREST_CLAMP]), clamp(texel, q0, q1), 0).r;
}

float shadow_cascade_soft(uint lighting, uint i, vec3 p, vec3 normal, vec3 sun) {
    uvec4 sh = g_lighting[lighting].f.shadows;
    mat4 m = g_lighting[lighting].f.cascade_view_proj[i];
    vec4 clip = m * vec4(p, 1.0);
    float size = float(sh.z);
    vec2 tc = (clip.xy * 0.5 + 0.5) * size - 0.5;
    int quadrant = int(sh.z / 2u);
    ivec2 q0 = ivec2(int(i % 2u), int(i / 2u)) * quadrant;
    ivec2 q1 = q0 + ivec2(quadrant - 1);
    float texel = g_lighting[lighting].f.cascade_texel[i];
    // Depth units per metre along the sun; sun-space x, y of the atlas.
    vec3 row0 = vec3(m[0][0], m[1][0], m[2][0]);
    vec3 row1 = vec3(m[0][1], m[1][1], m[2][1]);
    float per_metre = length(vec3(m[0][2], m[1][2], m[2][2]));
    // Receiver plane: depth change per texel along the atlas's x and y.
    float ns = max(dot(normal, sun), 0.05);
    vec2 slope = vec2(dot(normal, normalize(row0)), dot(normal, normalize(row1))) / ns * texel * per_metre;
    float bias = 0.5 * texel * per_metre;
    float tan_r = tan(max(g_lighting[lighting].f.sun.w, 1e-5));
    float base = float(sh.w & 0xffu) + 1.0;
    // Blocker search.
    float reach = clamp(clip.z / per_metre * tan_r / texel, base, SOFT_MAX_TEXELS);
    float step_search = reach / float(SOFT_SEARCH);
    float blockers = 0.0;
    float distance_sum = 0.0;
    for (int y = -SOFT_SEARCH; y <= SOFT_SEARCH; ++y) {
        for (int x = -SOFT_SEARCH; x <= SOFT_SEARCH; ++x) {
            vec2 o = vec2(x, y) * step_search;
            vec2 t = floor(tc + o + 0.5);
            float depth = shadow_atlas_depth(sh.x, ivec2(t), q0, q1);
            float d = (clip.z + dot(slope, t - tc) - bias - depth) / per_metre;
            if (d > 0.0 && d * tan_r / texel >= length(o) - base) {
                blockers += 1.0;
                distance_sum += d;
            }
        }
    }
    float radius = blockers > 0.0 ? clamp(distance_sum / blockers * tan_r / texel, base, SOFT_MAX_TEXELS) : base;
    // Disc filter of radius `radius` texels.
    float step_filter = radius / (float(SOFT_TAPS) + 0.5);
    float lit = 0.0;
    float total = 0.0;
    for (int y = -SOFT_TAPS; y <= SOFT_TAPS; ++y) {
        for (int x = -SOFT_TAPS; x <= SOFT_TAPS; ++x) {
            float w = clamp(float(SOFT_TAPS) + 1.0 - length(vec2(x, y)), 0.0, 1.0);
            if (w <= 0.0) {
                continue;
            }
            vec2 at = tc + vec2(x, y) * step_filter;
            vec2 b = floor(at);
            vec2 f = at - b;
            ivec2 t = ivec2(b);
            vec4 depths = vec4(shadow_atlas_depth(sh.x, t, q0, q1), shadow_atlas_depth(sh.x, t + ivec2(1, 0), q0, q1),
                               shadow_atlas_depth(sh.x, t + ivec2(0, 1), q0, q1),
                               shadow_atlas_depth(sh.x, t + ivec2(1, 1), q0, q1));
            // The receiver's plane at each of the four texels.
            float r = clip.z + dot(slope, b - tc) - bias;
            vec4 reference = vec4(r, r + slope.x, r + slope.y, r + slope.x + slope.y);
            vec4 pass = vec4(greaterThanEqual(depths, reference));
            float v = mix(mix(pass.x, pass.y, f.x), mix(pass.z, pass.w, f.x), f.y);
            lit += w * v;
            total += w;
        }
    }
    return lit / total;
}

// Visibility in cascade `i` of the surface point `world` with unit normal
// `normal`: the lookup point is offset along the normal (normal-offset bias,
// growing with the slope towards the sun so the whole PCF footprint stays
// above the caster's plane) and towards the sun by one texel.
float shadow_cascade(uint lighting, uint i, vec3 world, vec3 normal, vec3 sun) {
    float texel = g_lighting[lighting].f.cascade_texel[i];
    float radius = float(g_lighting[lighting].f.shadows.w);
    float cos_theta = clamp(dot(normal, sun), -1.0, 1.0);
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    float offset = texel * (0.5 + 1.5 * (radius + 1.0) * sin_theta);
    if ((g_lighting[lighting].f.models.w & LIGHTING_SOFT_SUN) != 0u) {
        // The receiver-plane bias keeps the wide filter off the surface: a
        // half-texel normal offset suffices and barely moves the penumbra.
        return shadow_cascade_soft(lighting, i, world + normal * (0.5 * texel) + sun * texel, normal, sun);
    }
    return shadow_cascade_pcf(lighting, i, world + normal * offset + sun * texel);
}

// Sun visibility beyond the shadow cascades (§9.5: horizon maps against
// shadow maps): the terrain's horizon map at `world` (horizon.glsl; baked
// once per terrain with the sky light, independent of the sun), or 1 where
// the frame has no horizon map (no terrain).
float distant_sun_visibility(uint lighting, vec3 world) {
    if (g_lighting[lighting].f.maps.y == 0u) {
        return 1.0;
    }
    return horizon_sun_visibility(lighting, world);
}

// 0 = in shadow, 1 = lit, filtered, at world point `world` with geometric
// normal `normal`, `view_depth` metres from the camera along its axis.
// Shadows off: 1. A sun below the horizon: 0 (softened over its disc).
// Beyond the last cascade: the horizon map (distant_sun_visibility), blended
// in over the last cascade's blend band, so shadows reach any distance.
float sun_visibility(uint lighting, vec3 world, vec3 normal, float view_depth) {
    uint mode = g_lighting[lighting].f.models.y;
    if (mode == SHADOWS_OFF) {
        return 1.0;
    }
    vec4 sun = g_lighting[lighting].f.sun;
    float above = smoothstep(-sun.w, sun.w, sun.z);
    if (above <= 0.0) {
        return 0.0;
    }
    if (mode == SHADOWS_HORIZON) {
        return min(above, horizon_sun_visibility(lighting, world));
    }
    uint count = min(g_lighting[lighting].f.shadows.y, uint(MAX_CASCADES));
    vec4 far = g_lighting[lighting].f.cascade_far;
    uint i = 0u;
    while (i < count && view_depth > far[i]) {
        ++i;
    }
    if (i >= count) {
        return distant_sun_visibility(lighting, world) * above;
    }
    vec3 n = normalize(normal);
    float v = shadow_cascade(lighting, i, world, n, sun.xyz);
    float start = i == 0u ? 0.0 : far[i - 1u];
    float band = SHADOW_BLEND_BAND * (far[i] - start);
    float t = band > 0.0 ? (view_depth - (far[i] - band)) / band : 0.0;
    if (t > 0.0) {
        float next = i + 1u < count ? shadow_cascade(lighting, i + 1u, world, n, sun.xyz)
                                    : distant_sun_visibility(lighting, world);
        v = mix(v, next, clamp(t, 0.0, 1.0));
    }
    return v * above;
}

#endif
