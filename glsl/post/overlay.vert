#version 460
// overlay.draw, vertex stage: the viewer's overlay (egui's meshes) pulled
// from the frame's upload region: vertices of 5 words (position x, y in
// points, uv u, v, RGBA8 premultiplied sRGB), then 32-bit indices already
// offset to the whole vertex list; one vertex per index (a triangle list).
#include "../include/heap.glsl"

layout(set = 0, binding = 2, std430) readonly buffer Geometry { uint words[]; } g_geometry[];

layout(push_constant) uniform Push {
    uvec4 handles;  // geometry (upload), font (sampled), index base (words), unused
    vec4 screen;    // swapchain width, height (pixels), pixels per point, unused
    vec4 uv_scale;  // the font atlas's used part of the image (u, v)
} pc;

layout(location = 0) out vec4 v_color;
layout(location = 1) out vec2 v_uv;

void main() {
    uint index = g_geometry[pc.handles.x].words[pc.handles.z + uint(gl_VertexIndex)];
    uint base = index * 5u;
    vec2 position = vec2(uintBitsToFloat(g_geometry[pc.handles.x].words[base]),
                         uintBitsToFloat(g_geometry[pc.handles.x].words[base + 1u]));
    vec2 uv = vec2(uintBitsToFloat(g_geometry[pc.handles.x].words[base + 2u]),
                   uintBitsToFloat(g_geometry[pc.handles.x].words[base + 3u]));
    v_color = unpackUnorm4x8(g_geometry[pc.handles.x].words[base + 4u]);
    v_uv = uv * pc.uv_scale.xy;
    vec2 pixels = position * pc.screen.z;
    gl_Position = vec4(pixels / pc.screen.xy * 2.0 - 1.0, 0.0, 1.0);
}
