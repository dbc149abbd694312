#version 460
// sky_light.transfer (§9.3 PRT, §9.5 AO and sky patches; ALGORITHMS.md §6):
// per height-field texel, from the traced horizons, the direct transfer
// T_x(ω) = max(0, n·ω) V(x, ω) / π projected onto the SH basis and onto the
// 8×8 sky patches, the sky visibility (1 − O) = ∫ T_x dω and the bent normal.
//
// Along azimuth φ_k the visible directions are z ∈ [z0, 1], z0 = max(z_h,
// z_t) (z_t: where n·ω = 0); with dω = dφ dz the elevation integrals are
// exact: ∫ max(0, n·ω) y_l^m dz = N_lm trig(mφ) (n_z A_lm(z0) + n_t B_lm(z0))
// with A, B tabulated over θ0 = acos z0 (src/lighting/sky_light/tables.rs),
// and the patch and AO integrals in closed form. Azimuths: the periodic
// trapezoid rule (weight 2π/K each; a patch boundary azimuth counts half
// to each side).
#include "../include/sky_light_bake.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // x: heights, y: horizons, z: tables, w: transfer (written)
    uvec4 grid;     // columns, rows, azimuths K, first row of this chunk
    uvec4 layout_;  // x: SH coefficients C, y: stride S = C + 64, z: surface (written), w: table entries
    vec4 spacing;   // dx, dy
} pc;

const int PATCHES = 8;

void main() {
    ivec2 grid = ivec2(pc.grid.xy);
    ivec2 p = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + pc.grid.w);
    if (p.x >= grid.x || p.y >= grid.y) {
        return;
    }
    uint K = pc.grid.z;
    uint C = pc.layout_.x;
    uint bands = C == 25u ? 5u : 3u;
    uint entries = pc.layout_.w;
    uint texel = uint(p.y) * uint(grid.x) + uint(p.x);
    vec3 n = bake_normal(pc.handles.x, grid, p, pc.spacing.xy);
    float dphi = 2.0 * BAKE_PI / float(K);
    float sh[25];
    for (int i = 0; i < 25; ++i) {
        sh[i] = 0.0;
    }
    float patches[PATCHES * PATCHES];
    for (int i = 0; i < PATCHES * PATCHES; ++i) {
        patches[i] = 0.0;
    }
    float visibility = 0.0;
    vec3 bent = vec3(0.0);
    uint per_sector = K / uint(PATCHES);
    for (uint k = 0u; k < K; ++k) {
        float phi = 2.0 * BAKE_PI * float(k) / float(K);
        vec2 u = vec2(cos(phi), sin(phi));
        float n_t = dot(n.xy, u);
        float z_h = unpackHalf2x16(g_bake_uints[pc.handles.y].v[texel * K + k]).x;
        float z0 = clamp(max(z_h, bake_terminator(n.z, n_t)), -1.0, 1.0);
        float w = dphi / BAKE_PI;
        visibility += w * bake_cosine_integral(n.z, n_t, z0, 1.0);
        bent += dphi * vec3(u * (bake_circle(1.0) - bake_circle(z0)), 0.5 * (1.0 - z0 * z0));
        // SH: table lookup at θ0, linear in θ.
        float f = acos(z0) / BAKE_PI * float(entries - 1u);
        uint j = min(uint(f), entries - 2u);
        float a = f - float(j);
        uint row0 = j * 32u;
        uint row1 = row0 + 32u;
        for (uint l = 0u; l < bands; ++l) {
            for (uint m = 0u; m <= l; ++m) {
                uint q = 2u * (l * (l + 1u) / 2u + m);
                float A = mix(g_bake_floats[pc.handles.z].v[row0 + q], g_bake_floats[pc.handles.z].v[row1 + q], a);
                float B = mix(g_bake_floats[pc.handles.z].v[row0 + q + 1u],
                              g_bake_floats[pc.handles.z].v[row1 + q + 1u], a);
                float s = w * (n.z * A + n_t * B);
                uint c = l * (l + 1u);
                if (m == 0u) {
                    sh[c] += s;
                } else {
                    sh[c + m] += s * cos(float(m) * phi);
                    sh[c - m] += s * sin(float(m) * phi);
                }
            }
        }
        // Patches: z bins of the upper hemisphere, one azimuth sector (half
        // to each side on a sector boundary).
        uint sector = k / per_sector;
        bool boundary = k % per_sector == 0u;
        uint previous = (sector + uint(PATCHES) - 1u) % uint(PATCHES);
        for (int b = 0; b < PATCHES; ++b) {
            float z1 = max(float(b) / float(PATCHES), z0);
            float z2 = float(b + 1) / float(PATCHES);
            if (z2 > z1) {
                float v = w * bake_cosine_integral(n.z, n_t, z1, z2);
                if (boundary) {
                    patches[b * PATCHES + int(sector)] += 0.5 * v;
                    patches[b * PATCHES + int(previous)] += 0.5 * v;
                } else {
                    patches[b * PATCHES + int(sector)] += v;
                }
            }
        }
    }
    uint S = pc.layout_.y;
    for (uint i = 0u; i < C; ++i) {
        g_bake_floats[pc.handles.w].v[texel * S + i] = sh[i];
    }
    for (uint i = 0u; i < uint(PATCHES * PATCHES); ++i) {
        g_bake_floats[pc.handles.w].v[texel * S + C + i] = patches[i];
    }
    float bent_length = length(bent);
    vec3 bent_normal = bent_length > 1e-12 ? bent / bent_length : n;
    uint o = texel * 8u;
    uint surface = pc.layout_.z;
    g_bake_floats[surface].v[o + 0u] = n.x;
    g_bake_floats[surface].v[o + 1u] = n.y;
    g_bake_floats[surface].v[o + 2u] = n.z;
    g_bake_floats[surface].v[o + 3u] = clamp(visibility, 0.0, 1.0);
    g_bake_floats[surface].v[o + 4u] = bent_normal.x;
    g_bake_floats[surface].v[o + 5u] = bent_normal.y;
    g_bake_floats[surface].v[o + 6u] = bent_normal.z;
    g_bake_floats[surface].v[o + 7u] = 0.0;
}
