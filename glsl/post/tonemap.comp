#version 460
// tonemap: HDR radiance → display sRGB (exposure, ACES fit by Narkowicz, sRGB
// transfer function), rounded deterministically into an RGBA8 storage image.
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;   // hdr (storage rgba32f), ldr (storage rgba8)
    uvec4 size;      // width, height
    vec4 exposure;   // x: exposure multiplier
} pc;

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
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
    vec3 ldr = srgb_encode(aces(max(hdr.rgb, vec3(0.0)) * pc.exposure.x));
    imageStore(g_images_rgba8[pc.handles.y], ivec2(id), vec4(ldr, clamp(hdr.a, 0.0, 1.0)));
}
