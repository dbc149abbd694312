#version 460
// lighting.reference: the Monte Carlo reference of sky light on the terrain
// (§9.2 references by Monte Carlo ray tracing; ALGORITHMS.md §6). Per
// height-field texel, `samples` paths over the bilinear height field with
// 0–2 Lambertian bounces of albedo ρ_b under the frame's sky (and sun):
// the sky-light map (rgb: radiance per unit albedo due to everything but the
// direct sun at the texel when the sun is a separate term; a: sky
// visibility) and the sun-visibility map. The quantity and the estimator are
// documented in src/lighting/reference/mod.rs; the CPU twin is
// src/lighting/reference/cpu.rs (same random numbers).
#include "../include/heap.glsl"
#include "../include/sky.glsl"
#include "../include/heightfield_trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// options.y flags
const uint REFERENCE_TEST_SKY = 1u;     // the sky is sky_a + sky_b · ω.z instead of sky_radiance (tests)
const uint REFERENCE_SUN_BOUNCES = 2u;  // bounce the sun also when it is a separate term

layout(push_constant) uniform Push {
    uvec4 handles;  // x: lighting frame (storage), y: height field (storage), z: sky-light map (rgba32f), w: sun visibility (r32f)
    uvec4 work;     // x: first row, y: rows, z: samples, w: seed
    uvec4 options;  // x: bounces, y: flags
    vec4 surface;   // xy: spacing (m), z: bounce albedo without override, w: ray origin lift (m)
    vec4 sky_a;     // test sky: constant rgb
    vec4 sky_b;     // test sky: rgb per unit ω.z
} pc;

const float PI = 3.14159265358979;
const uint ROTATION_SAMPLE = 0x0FFFFFFFu;
const float ONE_MINUS_ULP = 0.99999994;

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float random(uint key, uint s, uint dim) {
    uint x = pcg_hash(key ^ pcg_hash(s * 16u + dim));
    return float(x >> 8u) * (1.0 / 16777216.0);
}

vec2 hammersley(uint key, uint i, uint n, uint pair) {
    float a = (float(i) + 0.5) / float(n);
    float b = min(float(bitfieldReverse(i)) * 2.3283064e-10, ONE_MINUS_ULP);
    vec2 r = vec2(random(key, ROTATION_SAMPLE, 2u * pair), random(key, ROTATION_SAMPLE, 2u * pair + 1u));
    return min(fract(vec2(a, b) + r), vec2(ONE_MINUS_ULP));
}

void basis(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 cosine_direction(vec3 n, vec2 u) {
    vec3 t, b;
    basis(n, t, b);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    return normalize(t * (r * cos(phi)) + b * (r * sin(phi)) + n * sqrt(max(1.0 - u.x, 0.0)));
}

vec3 disc_direction(vec3 s, float radius, vec2 u) {
    vec3 t, b;
    basis(s, t, b);
    float r = radius * sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    return normalize(s + t * (r * cos(phi)) + b * (r * sin(phi)));
}

vec3 horizon_clamp(vec3 d) {
    d.z = max(d.z, 0.0);
    float len = length(d);
    return len > 1e-6 ? d / len : vec3(0.0, 0.0, 1.0);
}

vec3 environment(vec3 dir) {
    vec3 d = horizon_clamp(dir);
    if ((pc.options.y & REFERENCE_TEST_SKY) != 0u) {
        return pc.sky_a.rgb + pc.sky_b.rgb * d.z;
    }
    return sky_radiance(pc.handles.x, d);
}

bool escapes(Heightfield f, vec3 p, vec3 dir) {
    float t;
    vec2 g;
    return !hf_trace(f, p + vec3(0.0, 0.0, pc.surface.w), dir, t, g);
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    Heightfield f = hf_load(pc.handles.y, pc.surface.xy);
    uint c = id.x, r = pc.work.x + id.y;
    if (id.y >= pc.work.y || c >= uint(f.dims.x) || r >= uint(f.dims.y)) {
        return;
    }
    LightingFrame l = g_lighting[pc.handles.x].f;
    bool sun_in_env = (l.models.w & LIGHTING_SUN_IN_ENVIRONMENT) != 0u;
    bool bounced_sun = sun_in_env || (pc.options.y & REFERENCE_SUN_BOUNCES) != 0u;
    float albedo = (l.models.w & LIGHTING_ALBEDO_OVERRIDE) != 0u ? l.exposure.w : pc.surface.z;
    vec3 sun_term = l.sun_irradiance.rgb / PI;
    uint n = pc.work.z, bounces = pc.options.x;
    uint key = pcg_hash(pcg_hash(pcg_hash(pc.work.w) ^ c) ^ r);
    vec3 x = vec3(vec2(c, r) * f.spacing, hf_height(f, ivec2(c, r)));
    vec3 normal = hf_vertex_normal(f, ivec2(c, r));
    vec3 sum = vec3(0.0);
    uint escaped = 0u, sun_seen = 0u;
    for (uint s = 0u; s < n; ++s) {
        vec3 value = vec3(0.0);
        if (escapes(f, x, disc_direction(l.sun.xyz, l.sun.w, hammersley(key, s, n, 1u)))) {
            ++sun_seen;
            if (sun_in_env) {
                value += sun_term * max(dot(normal, l.sun.xyz), 0.0);
            }
        }
        vec3 dir = cosine_direction(normal, hammersley(key, s, n, 0u));
        vec3 origin = x;
        float throughput = 1.0;
        for (uint vertex = 0u; vertex <= bounces; ++vertex) {
            float t;
            vec2 g;
            if (!hf_trace(f, origin + vec3(0.0, 0.0, pc.surface.w), dir, t, g)) {
                value += throughput * environment(dir);
                escaped += vertex == 0u ? 1u : 0u;
                break;
            }
            if (vertex == bounces) {
                break;
            }
            throughput *= albedo;
            vec3 hit = origin + vec3(0.0, 0.0, pc.surface.w) + dir * t;
            vec3 n_y = hf_normal(f, g);
            uint dim = 4u * (vertex + 1u);
            float cos_sun = dot(n_y, l.sun.xyz);
            if (bounced_sun && cos_sun > 0.0) {
                vec2 u = vec2(random(key, s, dim + 2u), random(key, s, dim + 3u));
                if (escapes(f, hit, disc_direction(l.sun.xyz, l.sun.w, u))) {
                    value += throughput * sun_term * cos_sun;
                }
            }
            dir = cosine_direction(n_y, vec2(random(key, s, dim), random(key, s, dim + 1u)));
            origin = hit;
        }
        sum += value;
    }
    float inv = 1.0 / float(n);
    imageStore(g_images_rgba32f[pc.handles.z], ivec2(c, r), vec4(sum * inv, float(escaped) * inv));
    imageStore(g_images_r32f[pc.handles.w], ivec2(c, r), vec4(float(sun_seen) * inv));
}
