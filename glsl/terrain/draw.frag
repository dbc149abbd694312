#version 460
// terrain.draw: sun (Lambert) and sky ambient over a slope/altitude albedo,
// with haze; writes HDR radiance and view-space depth.
#include "../include/atmosphere.glsl"

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;
    vec4 forward;
    vec4 sun;
} pc;

layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

vec3 albedo(vec3 n, float h) {
    vec3 grass = vec3(0.20, 0.28, 0.10);
    vec3 rock = vec3(0.36, 0.33, 0.30);
    vec3 snow = vec3(0.90, 0.92, 0.95);
    float slope = 1.0 - n.z;
    vec3 a = mix(grass, rock, smoothstep(0.18, 0.35, slope));
    float snow_line = pc.sun.w;
    return mix(a, snow, smoothstep(snow_line, snow_line + 60.0, h) * (1.0 - smoothstep(0.35, 0.55, slope)));
}

void main() {
    vec3 n = normalize(in_normal);
    vec3 sun = normalize(pc.sun.xyz);
    vec3 a = albedo(n, in_world.z);
    vec3 sky_ambient = mix(SKY_HORIZON, SKY_ZENITH, 0.5 + 0.5 * n.z) * (0.5 + 0.5 * n.z);
    vec3 radiance = a * (SUN_RADIANCE * max(dot(n, sun), 0.0) + sky_ambient);
    vec3 to_point = in_world - pc.eye.xyz;
    float dist = length(to_point);
    out_color = vec4(apply_haze(radiance, dist, to_point / max(dist, 1e-6), sun), 1.0);
    out_depth = dot(to_point, pc.forward.xyz);
}
