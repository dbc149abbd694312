#version 460
// lighting.transmittance: the transmittance from (r, μ) to the top of the
// atmosphere (Bruneton 2017; Hillaire 2020 §5.1), 256×64, by a midpoint
// rule over the extinction of Rayleigh, Mie and ozone. CPU twin:
// src/lighting/atmosphere/twin.rs.
#define ATMOSPHERE_LUT_PASS
#include "../include/atmosphere_physical.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

const uint STEPS = 256u;  // dt ≤ 0.4 km at the zenith: the Mie layer (1.2 km) within 0.5 %

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.x || id.y >= pc.size.y) {
        return;
    }
    Atmosphere a = atmosphere_of(pc.handles.x, pc.ozone, pc.albedo.w, pc.sun.w);
    vec2 unit = vec2(id) / max(vec2(pc.size.xy) - 1.0, vec2(1.0));
    vec2 r_mu = atmosphere_transmittance_r_mu(a, unit);
    float r = r_mu.x;
    float mu = r_mu.y;
    float length_km = atmosphere_distance_to_top(a, r, mu);
    float dt = length_km / float(STEPS);
    vec3 depth = vec3(0.0);
    for (uint i = 0u; i < STEPS; ++i) {
        float t = (float(i) + 0.5) * dt;
        float radius = sqrt(max(r * r + t * t + 2.0 * r * mu * t, 0.0));
        depth += atmosphere_extinction(a, atmosphere_densities(a, radius - a.bottom)) * dt;
    }
    imageStore(g_images_rgba32f[pc.handles.y], ivec2(id), vec4(exp(-depth), 1.0));
}
