#version 460
// sky_light.horizon (§9.5, Hoffman's horizon mapping; ALGORITHMS.md §6): per
// height-field texel and for K azimuths φ_k = 2πk/K (+X towards +Y), march
// the field outwards with exponentially growing steps (3 % of the distance,
// at least one texel: 10 % skipped narrow far ridges, +0.008 sky visibility
// against the Monte Carlo reference at 5× relief, +0.003 now) and keep the
// highest elevation of the terrain. Writes per (texel, azimuth) packHalf2x16(z_h,
// d): z_h = sin of the horizon elevation (−1: nothing above the nadir),
// d = distance to the horizon point in units of the smaller spacing; and the
// sun horizon map (every K/16-th azimuth, the angle in radians) in 2×2
// tiles of 4 azimuths each.
#include "../include/sky_light_bake.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // x: heights, y: horizons (written), z: horizon map (storage image)
    uvec4 grid;     // columns, rows, azimuths K, first row of this chunk
    vec4 spacing;   // dx, dy, highest height of the field, unused
} pc;

void main() {
    ivec2 grid = ivec2(pc.grid.xy);
    ivec2 p = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + pc.grid.w);
    if (p.x >= grid.x || p.y >= grid.y) {
        return;
    }
    uint K = pc.grid.z;
    vec2 spacing = pc.spacing.xy;
    float step0 = min(spacing.x, spacing.y);
    float h0 = bake_height(pc.handles.x, grid, p);
    float rise = pc.spacing.z - h0;
    vec2 origin = vec2(p) * spacing;
    vec2 far = vec2(grid - 1) * spacing;
    uint base = (uint(p.y) * uint(grid.x) + uint(p.x)) * K;
    vec4 map[4] = vec4[4](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
    for (uint k = 0u; k < K; ++k) {
        float phi = 2.0 * BAKE_PI * float(k) / float(K);
        vec2 dir = vec2(cos(phi), sin(phi));
        float best = -1e30;
        float best_t = 0.0;
        float t = step0;
        for (int i = 0; i < 4096; ++i) {
            vec2 q = origin + t * dir;
            if (any(lessThan(q, vec2(-1e-3 * step0))) || any(greaterThan(q, far + 1e-3 * step0))) {
                break;
            }
            // Nothing further can rise above the best elevation so far.
            if (rise / t <= best) {
                break;
            }
            float slope = (bake_height_bilinear(pc.handles.x, grid, q / spacing) - h0) / t;
            if (slope > best) {
                best = slope;
                best_t = t;
            }
            t += max(step0, 0.03 * t);
        }
        float z_h = best < -1e29 ? -1.0 : best * inversesqrt(1.0 + best * best);
        g_bake_uints[pc.handles.y].v[base + k] = packHalf2x16(vec2(z_h, best_t / step0));
        uint per_map = K / 16u;
        if (k % per_map == 0u) {
            uint j = k / per_map;
            map[j / 4u][j % 4u] = best < -1e29 ? -0.5 * BAKE_PI : atan(best);
        }
    }
    for (int tile = 0; tile < 4; ++tile) {
        ivec2 at = p + ivec2(tile & 1, tile >> 1) * grid;
        imageStore(g_images_rgba32f[pc.handles.z], at, map[tile]);
    }
}
