#version 460
// texturing.finish (dissertation §8.2: "normals and final colour into the
// atlas"; ALGORITHMS.md §4): each dirty tile's texels, border included, go
// to its slot in the atlas textures: sRGB-encoded colour, and the normal of
// the layers' displacement alone (terrain.draw adds it to the mesh normal,
// so lighting stays dynamic) with the dominant layer's index in alpha
// (index / 255; the class AOV, src/view/aov.rs).
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/surface_layers.glsl"
#include "../include/texture_tiles.glsl"

vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
    TileJob job;
    uvec2 local;
    vec2 xy;
    if (!tile_texel(job, local, xy)) {
        return;
    }
    LayerState s = unpack_state(g_texel_states[pc.handles.y].t[gl_GlobalInvocationID.x]);
    ivec2 at = ivec2(job.tile.zw + local);
    imageStore(g_images_rgba8[job.images.x], at, vec4(linear_to_srgb(s.color), 1.0));
    vec3 n = normalize(vec3(-s.extra, 1.0));
    imageStore(g_images_rgba8[job.images.y], at, vec4(n * 0.5 + 0.5, float(s.dominant) / 255.0));
}
