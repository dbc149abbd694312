// The bindless descriptor heap (src/vulkan/heap.rs): one set, four arrays,
// indexed by handles passed in push constants.
#ifndef ALPENGLOW_HEAP_GLSL
#define ALPENGLOW_HEAP_GLSL

#extension GL_EXT_nonuniform_qualifier : require

layout(set = 0, binding = 0) uniform texture2D g_textures[];
layout(set = 0, binding = 0) uniform utexture2D g_utextures[];  // the same heap, unsigned-integer views
layout(set = 0, binding = 1, rgba32f) uniform image2D g_images_rgba32f[];
layout(set = 0, binding = 1, rgba8) uniform image2D g_images_rgba8[];
layout(set = 0, binding = 1, r32f) uniform image2D g_images_r32f[];
layout(set = 0, binding = 1, rg32f) uniform image2D g_images_rg32f[];
layout(set = 0, binding = 1, rgba16f) uniform image2D g_images_rgba16f[];
layout(set = 0, binding = 1, rg32ui) uniform uimage2D g_uimages_rg32ui[];
layout(set = 0, binding = 3) uniform sampler g_samplers[];

#define SAMPLER_LINEAR_CLAMP 0
#define SAMPLER_NEAREST_CLAMP 1
#define SAMPLER_LINEAR_REPEAT 2
#define SAMPLER_NEAREST_REPEAT 3

#define POSITIVE_INFINITY uintBitsToFloat(0x7f800000u)

#endif
