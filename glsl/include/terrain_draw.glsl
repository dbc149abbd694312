// Push constants of terrain.draw (src/terrain/shading.rs, TerrainDrawPush).
#ifndef ALPENGLOW_TERRAIN_DRAW_GLSL
#define ALPENGLOW_TERRAIN_DRAW_GLSL

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;      // xyz, w = d0 (sketch-atlas spacing, metres)
    vec4 forward;  // xyz: camera forward axis; w = pixel footprint per metre of depth
    vec4 sun;      // xyz: direction towards the sun; w = snow line (m)
    vec4 params;   // x = detail amplitude, y = detail H, z = noise tile handle (bits), w = flags (bits)
} pc;

// flags: bits 0–2 view, bit 3 detail on, bits 8–31 grid side N.
const uint VIEW_SHADED = 0u;
const uint VIEW_IMPORTANCE = 1u;
const uint VIEW_DENSITY_RATIO = 2u;
const uint VIEW_SPLIT_OCTAVE = 3u;
const uint VIEW_WIREFRAME = 4u;

uint draw_flags() {
    return floatBitsToUint(pc.params.w);
}

#endif
