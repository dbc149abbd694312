#version 460
// terrain.shadow, vertex stage (§9.5): the warped geometry image that
// terrain.warp wrote (world-space positions and normals) into one cascade
// of the shadow atlas, pushed away from the sun by a slope-scaled bias.
// Push constants: src/lighting/shadows/mod.rs, ShadowCasterPush.

layout(location = 0) in vec4 in_position;  // xyz, w = split octave
layout(location = 1) in vec4 in_normal;    // xyz, w = debug scalar

layout(push_constant) uniform Push {
    mat4 view_proj;   // world → atlas clip space of the cascade
    vec4 sun_texel;   // xyz: towards the sun, w: texel size (m)
    uvec4 handles;    // unused
} pc;

void main() {
    vec3 sun = pc.sun_texel.xyz;
    float texel = pc.sun_texel.w;
    vec3 n = normalize(in_normal.xyz);
    // Slope-scaled bias: half a texel plus half a texel per unit of tan θ
    // (θ between the normal and the sun), capped.
    float c = clamp(abs(dot(n, sun)), 1e-3, 1.0);
    float tan_theta = min(sqrt(1.0 - c * c) / c, 4.0);
    vec3 p = in_position.xyz - sun * texel * (0.5 + 0.5 * tan_theta);
    gl_Position = pc.view_proj * vec4(p, 1.0);
}
