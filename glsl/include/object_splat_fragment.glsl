// Per-fragment part of the object-space splat primitives (dissertation
// §10.3): the weight is the kernel texel at the perspective-correctly
// interpolated (u, v); the clip lines (§10.2.4) are tested in the tangent
// coordinates (2u−1, 2v−1)·R, object units, as splat_fragment.glsl tests them.
#ifndef ALPENGLOW_OBJECT_SPLAT_FRAGMENT_GLSL
#define ALPENGLOW_OBJECT_SPLAT_FRAGMENT_GLSL

#include "object_splat.glsl"

layout(location = 0) in vec3 in_position;     // camera space
layout(location = 1) in vec2 in_uv;           // kernel texture coordinates
layout(location = 2) flat in vec4 in_normal;  // n (camera), w: disk radius (object units)
layout(location = 3) flat in vec4 in_clip;
layout(location = 4) flat in vec4 in_color;

// The kernel weight, or 0 outside the disk or beyond a clip line.
float object_splat_weight() {
    float w = texture(sampler2D(g_textures[pc.handles.w], g_samplers[SAMPLER_LINEAR_CLAMP]), in_uv).r;
    vec2 uv = (2.0 * in_uv - 1.0) * in_normal.w;
    if (dot(uv, vec2(cos(in_clip.x), sin(in_clip.x))) > in_clip.y ||
        dot(uv, vec2(cos(in_clip.z), sin(in_clip.z))) > in_clip.w) {
        return 0.0;
    }
    return w;
}

#endif
