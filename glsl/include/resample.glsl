// The resampling post passes (post.resolve, post.distortion, post.motion_blur;
// src/post/resample.rs): images read through the heap's sampled arrays by
// texelFetch (float or uint, any format), written through the storage array
// of their format, chosen by a format code (`StorageFormat` in Rust).
#ifndef ALPENGLOW_RESAMPLE_GLSL
#define ALPENGLOW_RESAMPLE_GLSL

#include "heap.glsl"

#extension GL_EXT_samplerless_texture_functions : require

// Further views of the heap's sampled (binding 0) and storage (binding 1)
// arrays, for the formats of the simulator AOVs.
layout(set = 0, binding = 0) uniform utexture2D g_utextures[];
layout(set = 0, binding = 1, rgba16f) uniform image2D g_images_rgba16f[];
layout(set = 0, binding = 1, rg32f) uniform image2D g_images_rg32f[];
layout(set = 0, binding = 1, rg32ui) uniform uimage2D g_uimages_rg32ui[];
layout(set = 0, binding = 1, r32ui) uniform uimage2D g_uimages_r32ui[];

// `StorageFormat` codes: float formats first, then the uint ones.
#define FORMAT_RGBA32F 0u
#define FORMAT_RGBA16F 1u
#define FORMAT_RG32F 2u
#define FORMAT_R32F 3u
#define FORMAT_RGBA8 4u
#define FORMAT_RG32UI 5u
#define FORMAT_R32UI 6u

// `ImageKind` codes.
#define KIND_FILTERED 0u
#define KIND_EXACT 1u
#define KIND_MOTION 2u

bool format_is_uint(uint format) {
    return format >= FORMAT_RG32UI;
}

void store_float(uint format, uint handle, ivec2 p, vec4 v) {
    switch (format) {
    case FORMAT_RGBA32F:
        imageStore(g_images_rgba32f[handle], p, v);
        break;
    case FORMAT_RGBA16F:
        imageStore(g_images_rgba16f[handle], p, v);
        break;
    case FORMAT_RG32F:
        imageStore(g_images_rg32f[handle], p, v);
        break;
    case FORMAT_R32F:
        imageStore(g_images_r32f[handle], p, v);
        break;
    default:
        imageStore(g_images_rgba8[handle], p, v);
        break;
    }
}

void store_uint(uint format, uint handle, ivec2 p, uvec4 v) {
    if (format == FORMAT_RG32UI) {
        imageStore(g_uimages_rg32ui[handle], p, v);
    } else {
        imageStore(g_uimages_r32ui[handle], p, v);
    }
}

// Copies texel `q` of the source into texel `p` of the target, bit for bit.
void copy_texel(uint format, uint source, uint target, ivec2 q, ivec2 p) {
    if (format_is_uint(format)) {
        store_uint(format, target, p, texelFetch(g_utextures[source], q, 0));
    } else {
        store_float(format, target, p, texelFetch(g_textures[source], q, 0));
    }
}

// Bilinear interpolation at `q` in texel coordinates (texel k's centre at
// q = k), clamped to the edge; taps of weight 0 are skipped so that an
// infinite texel (sky depth) next to the sample does not make it NaN. The
// CPU twin (`bilinear` in src/post/resample.rs) adds in the same order.
vec4 bilinear(uint handle, vec2 q, ivec2 size) {
    q = clamp(q, vec2(-1.0), vec2(size));
    vec2 f = floor(q);
    vec2 t = q - f;
    ivec2 base = ivec2(f);
    vec4 sum = vec4(0.0);
    for (int dy = 0; dy < 2; dy++) {
        float wy = dy == 0 ? 1.0 - t.y : t.y;
        for (int dx = 0; dx < 2; dx++) {
            float w = (dx == 0 ? 1.0 - t.x : t.x) * wy;
            if (w > 0.0) {
                ivec2 tap = clamp(base + ivec2(dx, dy), ivec2(0), size - 1);
                sum += w * texelFetch(g_textures[handle], tap, 0);
            }
        }
    }
    return sum;
}

#endif
