#version 460
// overlay.draw, fragment stage: the vertex colour times the font atlas
// (both premultiplied), blended over the swapchain image as egui expects
// of an 8-bit sRGB-encoded target (blending on the encoded values).
#include "../include/heap.glsl"

layout(push_constant) uniform Push {
    uvec4 handles;  // geometry (upload), font (sampled), index base (words), unused
    vec4 screen;
    vec4 uv_scale;
} pc;

layout(location = 0) in vec4 v_color;
layout(location = 1) in vec2 v_uv;
layout(location = 0) out vec4 o_color;

void main() {
    vec4 texel = texture(sampler2D(g_textures[pc.handles.y], g_samplers[SAMPLER_LINEAR_CLAMP]), v_uv);
    o_color = v_color * texel;
}
