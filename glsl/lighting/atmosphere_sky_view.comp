#version 460
// lighting.sky_view: the sky's radiance seen from the camera's altitude
// (Hillaire 2020 §5.3): latitude–longitude around the sun's azimuth with
// the non-linear horizon mapping (atmosphere_sky_view_angles), single
// scattering by Rayleigh and Mie with the sun's transmittance from the
// transmittance table plus the multiple scattering Ψ_ms, in absolute
// units (× the solar irradiance at the top of the atmosphere). Below the
// horizon: the in-scattering between the camera and the ground (no ground).
#define ATMOSPHERE_LUT_PASS
#include "../include/atmosphere_physical.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

const uint STEPS = 32u;

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.x || id.y >= pc.size.y) {
        return;
    }
    uint lighting = pc.handles.x;
    Atmosphere a = atmosphere_of(lighting, pc.ozone, pc.albedo.w, pc.sun.w);
    float r = a.bottom + atmosphere_camera_altitude(lighting, a);
    vec2 unit = vec2(id) / max(vec2(pc.size.xy) - 1.0, vec2(1.0));
    vec2 angles = atmosphere_sky_view_angles(a, r, unit);
    float phi = angles.x;
    float theta = angles.y;
    vec3 dir = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
    vec3 s = g_lighting[lighting].f.sun.xyz;
    float mu_s = clamp(s.z / max(length(s), 1e-20), -1.0, 1.0);
    vec3 sun = vec3(sqrt(max(1.0 - mu_s * mu_s, 0.0)), 0.0, mu_s);
    AtmosphereMarch m = atmosphere_march(a, pc.handles.zw, vec3(0.0, 0.0, r), dir, sun, STEPS, false, true, vec3(0.0));
    imageStore(g_images_rgba32f[pc.handles.y], ivec2(id), vec4(m.radiance * pc.sun.rgb, 1.0));
}
