#version 460
// terrain.draw, fragment stage: the rasterized surface sample shaded by
// glsl/include/terrain_shade.glsl (§7.4.3, §8.2, §9). Writes HDR radiance
// (absolute), view depth, the lighting AOVs, the world shading normal and
// the semantic class.
#include "../include/terrain_draw.glsl"
#include "../include/terrain_shade.glsl"

layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in float in_split;
layout(location = 3) in float in_debug;
layout(location = 4) in vec2 in_grid;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_depth;
layout(location = 2) out vec2 out_visibility;
layout(location = 3) out vec4 out_normal;
layout(location = 4) out uvec2 out_ids;

void main() {
    TerrainParams p = TerrainParams(pc.eye, pc.forward, pc.lighting.x, pc.detail_amplitude, pc.detail_h, pc.noise_tile,
                                    pc.texturing_frame);
    TerrainSample s = TerrainSample(in_world, in_normal, in_split, in_debug, in_grid, fwidth(in_grid));
    TerrainShaded o = shade_terrain(p, s);
    out_color = vec4(o.radiance, 1.0);
    out_depth = o.depth;
    out_visibility = o.visibility;
    out_normal = vec4(o.normal, 1.0);
    out_ids = uvec2(o.semantic, 0u);
}
