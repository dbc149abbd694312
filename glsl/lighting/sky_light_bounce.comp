#version 460
// sky_light.bounce (§9.4, eq. 9.9–9.11; ALGORITHMS.md §6): one
// interreflection bounce of the transfer. Directions below the horizon of
// azimuth φ_k (and above the terminator) see the terrain; its outgoing
// radiance is approximated by that of the horizon point y_k:
//   T^k(x) = T^0(x) + ρ_b Σ_k (Δφ/π) ∫_{z_t}^{z_h} max(0, n·ω) dz · T^{k−1}(y_k)
// for every SH and patch coefficient alike (the transfer is linear).
#include "../include/sky_light_bake.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // x: surface (normals), y: horizons, z: previous bounce, w: direct transfer
    uvec4 grid;     // columns, rows, azimuths K, first row of this chunk
    uvec4 layout_;  // x: stride S, y: this bounce (written)
    vec4 params;    // dx, dy, bounce albedo ρ_b
} pc;

void main() {
    ivec2 grid = ivec2(pc.grid.xy);
    ivec2 p = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + pc.grid.w);
    if (p.x >= grid.x || p.y >= grid.y) {
        return;
    }
    uint K = pc.grid.z;
    uint S = pc.layout_.x;
    uint texel = uint(p.y) * uint(grid.x) + uint(p.x);
    vec3 n = vec3(g_bake_floats[pc.handles.x].v[texel * 8u], g_bake_floats[pc.handles.x].v[texel * 8u + 1u],
                  g_bake_floats[pc.handles.x].v[texel * 8u + 2u]);
    vec2 spacing = pc.params.xy;
    float step0 = min(spacing.x, spacing.y);
    float dphi = 2.0 * BAKE_PI / float(K);
    float acc[89];
    for (uint i = 0u; i < S; ++i) {
        acc[i] = 0.0;
    }
    for (uint k = 0u; k < K; ++k) {
        float phi = 2.0 * BAKE_PI * float(k) / float(K);
        vec2 u = vec2(cos(phi), sin(phi));
        float n_t = dot(n.xy, u);
        vec2 hd = unpackHalf2x16(g_bake_uints[pc.handles.y].v[texel * K + k]);
        float z_t = bake_terminator(n.z, n_t);
        if (hd.x <= z_t) {
            continue;
        }
        float w = dphi / BAKE_PI * bake_cosine_integral(n.z, n_t, z_t, min(hd.x, 1.0));
        vec2 q = (vec2(p) * spacing + hd.y * step0 * u) / spacing;
        ivec2 hit = clamp(ivec2(round(q)), ivec2(0), grid - 1);
        uint y = uint(hit.y) * uint(grid.x) + uint(hit.x);
        for (uint i = 0u; i < S; ++i) {
            acc[i] += w * g_bake_floats[pc.handles.z].v[y * S + i];
        }
    }
    for (uint i = 0u; i < S; ++i) {
        g_bake_floats[pc.layout_.y].v[texel * S + i] =
            g_bake_floats[pc.handles.w].v[texel * S + i] + pc.params.z * acc[i];
    }
}
