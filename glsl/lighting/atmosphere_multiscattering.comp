#version 460
// lighting.multiscattering: Hillaire 2020 §5.5, the isotropic approximation
// of multiple scattering of any order. Per altitude (v) and sun zenith
// cosine (u): over 64 directions of the sphere, the second-order radiance
// L_2 (isotropic phase, lit ground of the albedo) and the transfer f_ms of
// uniform unit illumination; Ψ_ms = L_2 / (1 − f_ms) (eq. 6–9), per unit
// solar irradiance. 32×32.
#define ATMOSPHERE_LUT_PASS
#include "../include/atmosphere_physical.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

const uint SIDE = 8u;  // SIDE × SIDE directions, uniform over the sphere
const uint STEPS = 20u;

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.x || id.y >= pc.size.y) {
        return;
    }
    Atmosphere a = atmosphere_of(pc.handles.x, pc.ozone, pc.albedo.w, pc.sun.w);
    vec2 unit = vec2(id) / max(vec2(pc.size.xy) - 1.0, vec2(1.0));
    float mu_s = 2.0 * unit.x - 1.0;
    float r = a.bottom + clamp(unit.y * (a.top - a.bottom), ATMO_MIN_ALTITUDE, a.top - a.bottom - ATMO_MIN_ALTITUDE);
    vec3 sun = vec3(sqrt(max(1.0 - mu_s * mu_s, 0.0)), 0.0, mu_s);
    vec3 origin = vec3(0.0, 0.0, r);
    vec3 l2 = vec3(0.0);
    vec3 f_ms = vec3(0.0);
    for (uint i = 0u; i < SIDE; ++i) {
        float cos_theta = 1.0 - 2.0 * (float(i) + 0.5) / float(SIDE);
        float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
        for (uint j = 0u; j < SIDE; ++j) {
            float phi = 2.0 * ATMO_PI * (float(j) + 0.5) / float(SIDE);
            vec3 dir = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
            AtmosphereMarch m = atmosphere_march(a, uvec2(pc.handles.z, pc.handles.z), origin, dir, sun, STEPS, true, false,
                                                 pc.albedo.rgb);
            l2 += m.radiance;
            f_ms += m.f_ms;
        }
    }
    // The sphere integrals with the isotropic phase 1/4π: the mean over the directions.
    float count = float(SIDE * SIDE);
    l2 /= count;
    f_ms /= count;
    vec3 psi = l2 / max(1.0 - f_ms, vec3(1e-3));
    imageStore(g_images_rgba32f[pc.handles.y], ivec2(id), vec4(psi, 1.0));
}
