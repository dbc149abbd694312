// Push constants of terrain.draw (src/terrain/shading.rs, TerrainDrawPush).
#ifndef ALPENGLOW_TERRAIN_DRAW_GLSL
#define ALPENGLOW_TERRAIN_DRAW_GLSL

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;      // xyz, w = d0 (sketch-atlas spacing, metres)
    vec4 forward;  // xyz: camera forward axis; w = pixel footprint per metre of depth
    uvec4 lighting;  // x: storage handle of the view's LightingFrame (lighting.glsl)
    float detail_amplitude;
    float detail_h;
    uint noise_tile;       // sampled handle of the wavelet noise tile
    uint texturing_frame;  // storage handle of the frame's TerrainTexturing constants
} pc;

#endif
