#version 460
// present.aov: one of a view's AOVs made visible for the viewer, written as
// display (sRGB-encoded) colours: view depth (log scale, near white to far
// dark; sky blue), world normal (n·0.5 + 0.5), class and instance id (a
// colour per id), motion (hue by direction, brightness by length, 16 px
// full), sun and sky visibility (grey).
#extension GL_EXT_samplerless_texture_functions : require
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // source (sampled), output (storage rgba8), kind, unused
    uvec4 size;     // width, height
} pc;

#define AOV_DEPTH 1u
#define AOV_NORMAL 2u
#define AOV_CLASS 3u
#define AOV_INSTANCE 4u
#define AOV_MOTION 5u
#define AOV_SUN_VISIBILITY 6u
#define AOV_SKY_VISIBILITY 7u

const vec3 SKY = vec3(0.35, 0.5, 0.75);

vec3 hue(float h) {
    return clamp(abs(mod(h * 6.0 + vec3(0.0, 4.0, 2.0), 6.0) - 3.0) - 1.0, 0.0, 1.0);
}

// A distinct colour per id (0: black).
vec3 id_color(uint id) {
    if (id == 0u) {
        return vec3(0.0);
    }
    uint h = id * 2654435761u;
    h ^= h >> 15;
    return 0.25 + 0.75 * hue(float(h & 0xffffu) / 65536.0);
}

void main() {
    ivec2 at = ivec2(gl_GlobalInvocationID.xy);
    if (at.x >= int(pc.size.x) || at.y >= int(pc.size.y)) {
        return;
    }
    uint kind = pc.handles.z;
    vec3 color = vec3(1.0, 0.0, 1.0);
    if (kind == AOV_CLASS || kind == AOV_INSTANCE) {
        uvec2 ids = texelFetch(g_utextures[pc.handles.x], at, 0).xy;
        color = id_color(kind == AOV_CLASS ? ids.x : ids.y);
    } else {
        vec4 v = texelFetch(g_textures[pc.handles.x], at, 0);
        if (kind == AOV_DEPTH) {
            // 1 m → 1, 100 km → 0.
            color = isinf(v.x) ? SKY : vec3(1.0 - clamp(log2(max(v.x, 1.0)) / log2(1e5), 0.0, 1.0));
        } else if (kind == AOV_NORMAL) {
            color = v.w == 0.0 ? vec3(0.0) : normalize(v.xyz) * 0.5 + 0.5;
        } else if (kind == AOV_MOTION) {
            float length_px = length(v.xy);
            float angle = atan(v.y, v.x) / 6.2831853 + 0.5;
            color = hue(angle) * clamp(length_px / 16.0, 0.0, 1.0);
        } else if (kind == AOV_SUN_VISIBILITY) {
            color = vec3(v.x);
        } else if (kind == AOV_SKY_VISIBILITY) {
            color = vec3(v.y);
        }
    }
    imageStore(g_images_rgba8[pc.handles.y], at, vec4(color, 1.0));
}
