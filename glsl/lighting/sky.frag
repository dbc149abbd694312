#version 460
// sky (§6.3; ALGORITHMS.md §6): the frame's sky model along each pixel's
// view ray plus the sun disc, in absolute units; view depth +inf; the
// lighting AOVs of sky pixels are (1, 1), the world normal 0 and the ids
// (class, instance) sky's (0, 0; src/view/aov.rs).
#include "../include/sky.glsl"
#include "../include/aov.glsl"

layout(push_constant) uniform Push {
    vec4 right;       // xyz: camera right · tan(fov_x/2)
    vec4 up;          // xyz: camera up · tan(fov_y/2)
    vec4 forward;     // xyz: camera forward
    uvec4 lighting;   // x: storage handle of the view's LightingFrame
} pc;

layout(location = 0) in vec2 in_ndc;
layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;
layout(location = 2) out vec2 out_visibility;
layout(location = 3) out vec4 out_normal;
layout(location = 4) out uvec2 out_ids;

void main() {
    // Vulkan NDC y points down the image: row 0 is the top, so negate.
    vec3 dir = normalize(pc.forward.xyz + in_ndc.x * pc.right.xyz - in_ndc.y * pc.up.xyz);
    uint l = pc.lighting.x;
    out_color = vec4(sky_radiance(l, dir) + sun_disc_radiance(l, dir), 1.0);
    out_depth = POSITIVE_INFINITY;
    out_visibility = vec2(1.0);
    out_normal = vec4(0.0);
    out_ids = uvec2(CLASS_SKY, 0u);
}
