#version 460
// aovs (src/post/aovs.rs; the simulator AOVs that follow from view depth
// and the cameras): a compute pass over the view's pixels. distance =
// |ray|·depth (+inf for sky); motion = pixel − its projection by the
// previous camera (the direction at infinity for sky pixels), 0 without a
// previous frame or where the point was behind the previous camera.
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 2, std430) readonly buffer AovConstants {
    vec4 right;     // xyz: camera right · tan(fov_x/2)
    vec4 up;        // xyz: camera up · tan(fov_y/2)
    vec4 forward;   // xyz: camera forward
    mat4 previous;  // previous world → clip after a translation by this eye
    vec4 size;      // width, height, 1 with a previous frame, 0
} g_aov[];

layout(push_constant) uniform Push {
    uvec4 handles;  // view depth (sampled), constants (storage), motion (storage rg32f), distance (storage r32f)
    uvec4 targets;  // width, height
} pc;

void main() {
    uint c = pc.handles.y;
    vec2 size = g_aov[c].size.xy;
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.targets.xy))) {
        return;
    }
    vec2 pixel = vec2(p) + 0.5;
    vec2 ndc = pixel / size * 2.0 - 1.0;
    // Vulkan NDC y points down the image, as in the sky pass.
    vec3 ray = g_aov[c].forward.xyz + ndc.x * g_aov[c].right.xyz - ndc.y * g_aov[c].up.xyz;
    float depth = texelFetch(sampler2D(g_textures[pc.handles.x], g_samplers[SAMPLER_NEAREST_CLAMP]), p, 0).r;
    bool sky = isinf(depth);
    float distance = sky ? POSITIVE_INFINITY : depth * length(ray);
    vec4 clip = g_aov[c].previous * (sky ? vec4(ray, 0.0) : vec4(ray * depth, 1.0));
    vec2 motion = vec2(0.0);
    if (g_aov[c].size.z != 0.0 && clip.w > 0.0) {
        motion = pixel - (clip.xy / clip.w * 0.5 + 0.5) * size;
    }
    imageStore(g_images_rg32f[pc.handles.z], p, vec4(motion, 0.0, 0.0));
    imageStore(g_images_r32f[pc.handles.w], p, vec4(distance));
}
