// Terrain shading's side of the surface layers (dissertation §8.2;
// src/surface/gpu_layout.rs, TexturingFrame; src/texturing/page_table.rs):
// the per-frame texturing constants, and for the atlas mode the walk of the
// frame's page table from the root to the tile covering world xy, whose
// colour and displacement normal are sampled bilinearly. Needs heap.glsl.
#ifndef ALPENGLOW_TEXTURE_ATLAS_GLSL
#define ALPENGLOW_TEXTURE_ATLAS_GLSL

#include "heap.glsl"
#include "detail_window.glsl"

#define MAX_PAGE_DEPTH 16
#define PAGE_LEAF 0x80000000u
#define PAGE_NONE 0xffffffffu
#define MAX_ATLAS_TEXTURES 32

const uint TEXTURING_CLASSIC = 0u;
const uint TEXTURING_DIRECT = 1u;
const uint TEXTURING_ATLAS = 2u;

// Per-frame texturing constants (TexturingFrame).
layout(set = 0, binding = 2, std430) readonly buffer TerrainTexturing {
    uvec4 handles;        // layers (storage), height texture (sampled), noise tile (sampled), mode
    uvec4 grid;           // columns, rows, layer count, 0
    vec4 spacing_range;   // spacing x, y, lowest and highest height
    uvec4 atlas;          // page table (storage), atlas texture count, atlas size (texels), 0
    vec4 extent;          // terrain rectangle x, y (metres), 0, 0
    uvec4 maps;           // input maps (sampled), w: bit k set when map k is present
    uvec4 color[MAX_ATLAS_TEXTURES / 4];   // sampled handles of the colour textures
    uvec4 normal[MAX_ATLAS_TEXTURES / 4];  // sampled handles of the normal textures
    uvec4 draw;           // terrain.draw: view (VIEW_*), detail on (0/1), grid side N, 0
    DetailWindow window;  // the streamed detail window direct texturing reads (detail_window.glsl)
} g_texturing[];

layout(set = 0, binding = 2, std430) readonly buffer PageTable { uvec4 w[]; } g_page_tables[];

#include "srgb.glsl"

// Colour (linear), displacement gradient and dominant layer (the nearest
// texel's normal alpha, texturing.finish) of the atlas at world xy; false
// when no tile covers it (nothing resident yet).
bool sample_atlas(uint texturing, vec2 xy, out vec3 color, out vec2 extra, out uint layer) {
    uvec4 atlas = g_texturing[texturing].atlas;
    uint table = atlas.x;
    uvec4 header = g_page_tables[table].w[0];
    vec2 uv = clamp(xy / g_texturing[texturing].extent.xy, vec2(0.0), vec2(1.0));
    uint r = header.x;
    for (int level = 0; level <= MAX_PAGE_DEPTH && r != PAGE_NONE && (r & PAGE_LEAF) == 0u; ++level) {
        uv *= 2.0;
        vec2 c = clamp(floor(uv), vec2(0.0), vec2(1.0));
        uv -= c;
        r = g_page_tables[table].w[1u + r][uint(c.y) * 2u + uint(c.x)];
    }
    if (r == PAGE_NONE || (r & PAGE_LEAF) == 0u) {
        r = header.y;
    }
    if (r == PAGE_NONE) {
        color = vec3(0.0);
        extra = vec2(0.0);
        layer = 0u;
        return false;
    }
    uint e = header.z + 2u * (r & ~PAGE_LEAF);
    vec4 rect = uintBitsToFloat(g_page_tables[table].w[e]);       // node min, node size
    uvec4 where = g_page_tables[table].w[e + 1u];                 // atlas origin, inner texels, texture
    vec2 texel = uintBitsToFloat(where.xy) + (xy - rect.xy) / rect.zw * uintBitsToFloat(where.z);
    vec2 at = texel / float(atlas.z);
    uint k = min(where.w, MAX_ATLAS_TEXTURES - 1u);
    uint color_handle = g_texturing[texturing].color[k / 4u][k % 4u];
    uint normal_handle = g_texturing[texturing].normal[k / 4u][k % 4u];
    color = srgb_to_linear(textureLod(sampler2D(g_textures[nonuniformEXT(color_handle)], g_samplers[SAMPLER_LINEAR_CLAMP]), at, 0.0).rgb);
    vec3 n = textureLod(sampler2D(g_textures[nonuniformEXT(normal_handle)], g_samplers[SAMPLER_LINEAR_CLAMP]), at, 0.0).xyz * 2.0 - 1.0;
    extra = -n.xy / max(n.z, 1e-3);
    // The nearest texel of the tile's own inner texels (a point on the
    // node's far edge must not read the neighbouring slot).
    vec2 origin = uintBitsToFloat(where.xy);
    float inner = uintBitsToFloat(where.z);
    ivec2 nearest = ivec2(clamp(floor(texel), origin, origin + vec2(inner - 1.0)));
    nearest = clamp(nearest, ivec2(0), ivec2(int(atlas.z) - 1));
    // A nearest-filtered lookup at the texel's centre rather than a
    // texelFetch: lavapipe 25.0's compute shaders return wrong texels for
    // some invocations of a non-uniformly indexed texelFetch (the compute
    // path's terrain.shade reported other layers than terrain.draw).
    vec2 centre = (vec2(nearest) + 0.5) / float(atlas.z);
    float a = textureLod(sampler2D(g_textures[nonuniformEXT(normal_handle)], g_samplers[SAMPLER_NEAREST_CLAMP]), centre, 0.0).a;
    layer = uint(round(a * 255.0));
    return true;
}

#endif
