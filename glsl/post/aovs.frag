#version 460
// aovs (src/post/aovs.rs; the AOV table in src/view/aov.rs): per pixel, the
// surface point X = eye + ray·depth of the view depth (ray through the pixel
// centre, ray·forward = 1), its Euclidean distance |ray|·depth (+inf for
// sky), and its motion: this pixel minus X projected by the previous
// frame's camera (sky: the direction at infinity, (ray, 0)); 0 on the
// view's first frame or where X was behind the previous camera.
#include "../include/heap.glsl"

layout(set = 0, binding = 2, std430) readonly buffer AovConstants {
    vec4 right;     // xyz: camera right · tan(fov_x/2)
    vec4 up;        // xyz: camera up · tan(fov_y/2)
    vec4 forward;   // xyz: camera forward
    mat4 previous;  // previous world → clip after a translation by this eye
    vec4 size;      // width, height, 1 with a previous frame, 0
} g_aov[];

layout(push_constant) uniform Push {
    uvec4 handles;  // view depth (sampled), constants (storage)
} pc;

layout(location = 0) out vec2 out_motion;
layout(location = 1) out float out_distance;

void main() {
    uint c = pc.handles.y;
    vec2 size = g_aov[c].size.xy;
    vec2 pixel = gl_FragCoord.xy;
    vec2 ndc = pixel / size * 2.0 - 1.0;
    // Vulkan NDC y points down the image, as in the sky pass.
    vec3 ray = g_aov[c].forward.xyz + ndc.x * g_aov[c].right.xyz - ndc.y * g_aov[c].up.xyz;
    float depth = texelFetch(sampler2D(g_textures[pc.handles.x], g_samplers[SAMPLER_NEAREST_CLAMP]), ivec2(pixel), 0).r;
    bool sky = isinf(depth);
    out_distance = sky ? POSITIVE_INFINITY : depth * length(ray);
    vec4 clip = g_aov[c].previous * (sky ? vec4(ray, 0.0) : vec4(ray * depth, 1.0));
    out_motion = vec2(0.0);
    if (g_aov[c].size.z != 0.0 && clip.w > 0.0) {
        out_motion = pixel - (clip.xy / clip.w * 0.5 + 0.5) * size;
    }
}
