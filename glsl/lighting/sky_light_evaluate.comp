#version 460
// lighting.sky_light (§9.3–9.5; ALGORITHMS.md §6): per height-field texel,
// the outgoing radiance per unit albedo from sky light (rgb) and the sky
// visibility (a) into the sky-light map, by mode:
//   sh      Σ_i T_i L_i (transfer · environment, eq. 9.7)
//   ao      visibility · E(bent normal) / π (eq. 9.18, 9.19)
//   patches Σ_p T_p L_p over the N×N sky patches
//   off     E(n) / π, unoccluded
// E from the environment's SH by the clamped-cosine convolution.
#include "../include/heap.glsl"
#include "../include/sh.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 2, std430) readonly buffer SkyLightFloats { float v[]; } g_sky_floats[];
layout(set = 0, binding = 2, std430) readonly buffer SkyLightEnvironment { vec4 v[]; } g_sky_environment[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: surface, y: transfer, z: environment, w: sky-light map (storage)
    uvec4 grid;     // columns, rows, mode (SKY_LIGHT_*), SH coefficients evaluated
    uvec4 layout_;  // x: SH coefficients baked C, y: stride S, z: patches per side (4 or 8)
} pc;

const uint SKY_LIGHT_OFF = 0u;
const uint SKY_LIGHT_SH = 2u;
const uint SKY_LIGHT_AO = 3u;
const uint SKY_LIGHT_PATCHES = 4u;

// E(n) / π from the environment's 25 SH coefficients.
vec3 irradiance_over_pi(uint environment, vec3 n) {
    float y[25];
    sh_basis(n, y);
    vec3 e = vec3(0.0);
    for (int i = 0; i < 25; ++i) {
        e += sh_clamped_cosine_over_pi(sh_band(i)) * y[i] * g_sky_environment[environment].v[i].rgb;
    }
    return e;
}

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.grid.x || p.y >= pc.grid.y) {
        return;
    }
    uint texel = p.y * pc.grid.x + p.x;
    uint surface = pc.handles.x;
    uint environment = pc.handles.z;
    vec3 n = vec3(g_sky_floats[surface].v[texel * 8u], g_sky_floats[surface].v[texel * 8u + 1u],
                  g_sky_floats[surface].v[texel * 8u + 2u]);
    float visibility = g_sky_floats[surface].v[texel * 8u + 3u];
    vec3 bent = vec3(g_sky_floats[surface].v[texel * 8u + 4u], g_sky_floats[surface].v[texel * 8u + 5u],
                     g_sky_floats[surface].v[texel * 8u + 6u]);
    uint S = pc.layout_.y;
    uint base = texel * S;
    vec3 radiance = vec3(0.0);
    uint mode = pc.grid.z;
    if (mode == SKY_LIGHT_SH) {
        for (uint i = 0u; i < pc.grid.w; ++i) {
            radiance += g_sky_floats[pc.handles.y].v[base + i] * g_sky_environment[environment].v[i].rgb;
        }
    } else if (mode == SKY_LIGHT_AO) {
        radiance = visibility * irradiance_over_pi(environment, bent);
    } else if (mode == SKY_LIGHT_PATCHES) {
        uint C = pc.layout_.x;
        if (pc.layout_.z == 8u) {
            for (uint k = 0u; k < 64u; ++k) {
                radiance += g_sky_floats[pc.handles.y].v[base + C + k] * g_sky_environment[environment].v[25u + k].rgb;
            }
        } else {
            for (uint k = 0u; k < 64u; ++k) {
                uint coarse = (k / 16u) * 4u + (k % 8u) / 2u;
                radiance +=
                    g_sky_floats[pc.handles.y].v[base + C + k] * g_sky_environment[environment].v[89u + coarse].rgb;
            }
        }
    } else {
        radiance = irradiance_over_pi(environment, n);
        visibility = 1.0;
    }
    imageStore(g_images_rgba32f[pc.handles.w], ivec2(p), vec4(max(radiance, vec3(0.0)), visibility));
}
