#version 460
// sky: analytic sky radiance along each pixel's view ray; depth +inf.
#include "../include/heap.glsl"
#include "../include/atmosphere.glsl"

layout(push_constant) uniform Push {
    vec4 right;    // xyz: camera right · tan(fov_x/2)
    vec4 up;       // xyz: camera up · tan(fov_y/2)
    vec4 forward;  // xyz: camera forward
    vec4 sun;      // xyz: towards the sun
} pc;

layout(location = 0) in vec2 in_ndc;
layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;

void main() {
    // Vulkan NDC y points down the image: row 0 is the top, so negate.
    vec3 dir = normalize(pc.forward.xyz + in_ndc.x * pc.right.xyz - in_ndc.y * pc.up.xyz);
    out_color = vec4(sky_radiance(dir, normalize(pc.sun.xyz)), 1.0);
    out_depth = POSITIVE_INFINITY;
}
