#version 460
// lighting.environment (§9.3, §9.5; ALGORITHMS.md §6): the frame's sky
// radiance projected onto 25 RGB SH coefficients and averaged over the sky
// patches (8×8 and 4×4: azimuth sector × z bin of the upper hemisphere).
// Quadrature: 128 equally spaced azimuths × 64 z rows, the rows a 4-point
// Gauss–Legendre rule in each of 16 z bins of width 1/8 (the patch bins of
// the upper hemisphere), exact for the zonal SH up to band 4; with LIGHTING_SUN_IN_ENVIRONMENT the sun adds a
// delta of its disc's irradiance. One workgroup; every sum is taken in a
// fixed order (deterministic).
#include "../include/heap.glsl"
#include "../include/sky.glsl"
#include "../include/sh.glsl"

layout(local_size_x = 32) in;

layout(set = 0, binding = 2, std430) writeonly buffer Environment { vec4 v[]; } g_environment_out[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: lighting frame, y: environment (written)
} pc;

const int AZIMUTHS = 128;
const int ROWS = 64;
const int SECTORS = 8;

shared vec3 s_sh[32][25];
shared vec3 s_sectors[32][SECTORS];
shared vec3 s_patches[64];

void main() {
    int t = int(gl_LocalInvocationID.x);
    uint lighting = pc.handles.x;
    vec3 sh[25];
    for (int i = 0; i < 25; ++i) {
        sh[i] = vec3(0.0);
    }
    vec3 sectors[SECTORS];
    for (int a = 0; a < SECTORS; ++a) {
        sectors[a] = vec3(0.0);
    }
    const float nodes[4] = float[4](-0.861136311594053, -0.339981043584856, 0.339981043584856, 0.861136311594053);
    const float weights[4] = float[4](0.347854845137454, 0.652145154862546, 0.652145154862546, 0.347854845137454);
    for (int row = 2 * t; row < 2 * t + 2; ++row) {
        int bin = row / 4;
        float z = -1.0 + (float(bin) + 0.5 + 0.5 * nodes[row % 4]) / 8.0;
        float wz = weights[row % 4] / 16.0;
        float r = sqrt(max(1.0 - z * z, 0.0));
        for (int i = 0; i < AZIMUTHS; ++i) {
            float phi = 2.0 * SH_PI * (float(i) + 0.5) / float(AZIMUTHS);
            vec3 dir = vec3(r * cos(phi), r * sin(phi), z);
            vec3 radiance = sky_radiance(lighting, dir) * wz;
            float y[25];
            sh_basis(dir, y);
            for (int c = 0; c < 25; ++c) {
                sh[c] += radiance * y[c];
            }
            sectors[i / (AZIMUTHS / SECTORS)] += radiance;
        }
    }
    for (int c = 0; c < 25; ++c) {
        s_sh[t][c] = sh[c];
    }
    for (int a = 0; a < SECTORS; ++a) {
        s_sectors[t][a] = sectors[a];
    }
    barrier();

    vec4 sun = g_lighting[lighting].f.sun;
    vec3 sun_e = g_lighting[lighting].f.sun_irradiance.rgb;
    bool sun_in = (g_lighting[lighting].f.models.w & LIGHTING_SUN_IN_ENVIRONMENT) != 0u;
    float cell = 2.0 * SH_PI / float(AZIMUTHS);
    uint out_ = pc.handles.y;
    if (t < 25) {
        vec3 sum = vec3(0.0);
        for (int q = 0; q < 32; ++q) {
            sum += s_sh[q][t];
        }
        sum *= cell;
        if (sun_in) {
            float y[25];
            sh_basis(sun.xyz, y);
            sum += sun_e * y[t];
        }
        g_environment_out[out_].v[t] = vec4(sum, 0.0);
    }
    // 8×8 patches: bin b = rows 32 + 4b .. 32 + 4b + 3 = threads 16 + 2b, 17 + 2b.
    float patch_solid_angle = 2.0 * SH_PI / 64.0;
    int sun_patch = -1;
    if (sun_in && sun.z > 0.0) {
        float phi = atan(sun.y, sun.x);
        phi = phi < 0.0 ? phi + 2.0 * SH_PI : phi;
        int a = min(int(phi / (2.0 * SH_PI) * float(SECTORS)), SECTORS - 1);
        int b = min(int(sun.z * 8.0), 7);
        sun_patch = b * 8 + a;
    }
    for (int k = t; k < 64; k += 32) {
        int b = k / 8;
        int a = k % 8;
        vec3 sum = s_sectors[16 + 2 * b][a] + s_sectors[17 + 2 * b][a];
        vec3 mean = sum * cell / patch_solid_angle;
        if (k == sun_patch) {
            mean += sun_e / patch_solid_angle;
        }
        s_patches[k] = mean;
        g_environment_out[out_].v[25 + k] = vec4(mean, 0.0);
    }
    barrier();
    if (t < 16) {
        int b = t / 4;
        int a = t % 4;
        vec3 sum = vec3(0.0);
        for (int db = 0; db < 2; ++db) {
            for (int da = 0; da < 2; ++da) {
                sum += s_patches[(2 * b + db) * 8 + 2 * a + da];
            }
        }
        g_environment_out[out_].v[89 + t] = vec4(0.25 * sum, 0.0);
    }
}
