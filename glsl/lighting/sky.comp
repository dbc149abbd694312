#version 460
// sky (§6.3; ALGORITHMS.md §6): a compute pass over every pixel of a view,
// each shaded by glsl/include/sky_pixel.glsl (the frame's sky model along
// the pixel's view ray plus the sun disc; view depth +inf; sky's AOVs).
// The compute path's terrain.shade shades the sky itself where the terrain
// leaves a pixel empty, so this pass runs on the hardware path and in
// scenes without terrain.
#include "../include/sky_pixel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    vec4 right;       // xyz: camera right · tan(fov_x/2)
    vec4 up;          // xyz: camera up · tan(fov_y/2)
    vec4 forward;     // xyz: camera forward
    uvec4 lighting;   // x: storage handle of the view's LightingFrame; y, z: width, height; w: ids (storage)
    uvec4 images;     // storage: radiance, view depth, lighting AOVs, normal
} pc;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    uvec2 size = pc.lighting.yz;
    if (any(greaterThanEqual(uvec2(pixel), size))) {
        return;
    }
    // Vulkan NDC y points down the image: row 0 is the top, so negate.
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 ray = pc.forward.xyz + ndc.x * pc.right.xyz - ndc.y * pc.up.xyz;
    store_sky_pixel(pc.lighting.x, ray, pixel, pc.images, pc.lighting.w);
}
