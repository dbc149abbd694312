#version 460
// terrain.draw: the grid vertices written by terrain.grid, as vertex input.
layout(location = 0) in vec4 in_position;
layout(location = 1) in vec4 in_normal;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;      // xyz
    vec4 forward;  // xyz: camera forward axis (view-space depth)
    vec4 sun;      // xyz: direction towards the sun
} pc;

layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;

void main() {
    out_world = in_position.xyz;
    out_normal = in_normal.xyz;
    gl_Position = pc.view_proj * vec4(in_position.xyz, 1.0);
}
