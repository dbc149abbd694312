#version 460
// tonemap: absolute HDR radiance → display sRGB: the frame's exposure
// multiplier (exposure.meter), a filmic tone curve (the ACES fit of Stephen
// Hill: RRT and ODT approximated, with the sRGB → ACES AP1 input and output
// matrices, so saturated colours desaturate towards white as real film
// does), the sRGB transfer function, rounded deterministically into an
// RGBA8 storage image.
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 2, std430) readonly buffer ExposureIn { float multiplier; float ev100; float mean_log2; float pad; } g_exposure[];

layout(push_constant) uniform Push {
    uvec4 handles;   // hdr (storage rgba32f), ldr (storage rgba8), exposure (storage buffer)
    uvec4 size;      // width, height
} pc;

const mat3 ACES_INPUT = mat3(0.59719, 0.07600, 0.02840, 0.35458, 0.90834, 0.13383, 0.04823, 0.01566, 0.83777);
const mat3 ACES_OUTPUT = mat3(1.60475, -0.10208, -0.00327, -0.53108, 1.10813, -0.07276, -0.07367, -0.00605, 1.07602);

vec3 rrt_and_odt(vec3 v) {
    vec3 a = v * (v + 0.0245786) - 0.000090537;
    vec3 b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return a / b;
}

vec3 aces_filmic(vec3 c) {
    return clamp(ACES_OUTPUT * rrt_and_odt(ACES_INPUT * c), 0.0, 1.0);
}

vec3 srgb_encode(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.x || id.y >= pc.size.y) {
        return;
    }
    vec4 hdr = imageLoad(g_images_rgba32f[pc.handles.x], ivec2(id));
    // Hill's fit maps scene-referred 1.0 ≈ white: mid grey (0.18) needs ×~1.7 headroom.
    float exposure = g_exposure[pc.handles.z].multiplier * 1.8;
    vec3 ldr = srgb_encode(aces_filmic(max(hdr.rgb, vec3(0.0)) * exposure));
    imageStore(g_images_rgba8[pc.handles.y], ivec2(id), vec4(ldr, clamp(hdr.a, 0.0, 1.0)));
}
