#version 460
// terrain.draw, vertex stage: the warped geometry image that terrain.warp
// wrote into this vertex buffer (render-to-vertex-buffer, §7.4.2).
#include "../include/terrain_draw.glsl"
#include "../include/texture_atlas.glsl"

layout(location = 0) in vec4 in_position;  // xyz, w = split octave
layout(location = 1) in vec4 in_normal;    // xyz, w = debug scalar

layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out float out_split;
layout(location = 3) out float out_debug;
layout(location = 4) out vec2 out_grid;

void main() {
    out_world = in_position.xyz;
    out_normal = in_normal.xyz;
    out_split = in_position.w;
    out_debug = in_normal.w;
    uint side = g_texturing[pc.texturing_frame].draw.z;
    uint index = uint(gl_VertexIndex);
    out_grid = vec2(index % side, index / side);
    gl_Position = pc.view_proj * vec4(in_position.xyz, 1.0);
}
