// The terrain's surface shading (dissertation §7.4.3 "Procedural Detail"
// and "Colour"; ALGORITHMS.md §3 items 6 and 8): per-pixel bump mapping with
// the detail octaves between the vertex's split octave and the pixel
// footprint, surface type from altitude, slope and orientation with
// turbulence-perturbed boundaries, or the surface layers (§8.2) per pixel or
// from the texture atlas; lit by the frame's sun (with shadows) and sky
// light, seen through aerial perspective (§9). Shared by terrain.draw's
// fragment stage and terrain.shade (the compute path's per-pixel shading of
// the visibility buffer), which differ only in how they find the surface
// sample.
#ifndef ALPENGLOW_TERRAIN_SHADE_GLSL
#define ALPENGLOW_TERRAIN_SHADE_GLSL

#include "heap.glsl"
#include "terrain_detail.glsl"
#include "bspline_height.glsl"
#include "surface_layers.glsl"
#include "texture_atlas.glsl"
#include "surface_lighting.glsl"
#include "aov.glsl"

// TerrainTexturing.draw.x: what the terrain shows.
const uint VIEW_SHADED = 0u;
const uint VIEW_IMPORTANCE = 1u;
const uint VIEW_DENSITY_RATIO = 2u;
const uint VIEW_SPLIT_OCTAVE = 3u;
const uint VIEW_WIREFRAME = 4u;

// What the shading of a view needs besides the surface sample (terrain.draw's
// push constants but for the projection).
struct TerrainParams {
    vec4 eye;      // xyz, w = d0 (sketch-atlas spacing, metres)
    vec4 forward;  // xyz: camera forward axis; w = pixel footprint per metre of depth
    uint lighting;  // storage handle of the view's LightingFrame (lighting.glsl)
    float detail_amplitude;
    float detail_h;
    uint noise_tile;       // sampled handle of the wavelet noise tile
    uint texturing_frame;  // storage handle of the frame's TerrainTexturing constants
};

// The surface at a pixel, interpolated from the warped grid's vertices.
struct TerrainSample {
    vec3 world;
    vec3 normal;  // the mesh normal (not normalised)
    float split;  // split octave
    float debug;  // debug scalar of the vertex
    vec2 grid;    // grid coordinates (column, row)
    vec2 grid_width;  // fwidth(grid): the wireframe's line width
};

// What the pixel shows: HDR radiance (absolute), view depth, the lighting
// AOVs, the world shading normal and the semantic class
// (src/view/aov.rs: 10 + the dominant surface layer; 1 in the debug views
// or where no atlas tile is resident).
struct TerrainShaded {
    vec3 radiance;
    float depth;
    vec2 visibility;
    vec3 normal;
    uint semantic;
};

// Layers of the built-in tree the classic surface types are reported as
// (src/terrain/shading.rs, CLASSIC_LAYERS): grass, dry grass, rock, snow.
const uint CLASSIC_LAYER[4] = uint[](1u, 3u, 0u, 6u);

// Blue → green → yellow → red for t in [0, 1].
vec3 ramp(float t) {
    t = clamp(t, 0.0, 1.0);
    return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
}

// Surface type → albedo. Boundaries are perturbed by low-frequency
// turbulence (the wavelet tile at coarse scales) before classification.
// `type`: the type with the largest share of the blend (0 grass, 1 dry
// grass, 2 rock, 3 snow; the first of equal shares).
vec3 albedo(vec3 n, vec3 p, uint tile, vec3 sun, float snow_line_base, out uint type) {
    // Turbulence needs no smooth derivative: one bilinear fetch per octave.
    float turb = 0.0;
    float scale = 1.0 / 180.0;
    float a = 1.0;
    for (int k = 0; k < 3; ++k) {
        vec2 uv = (p.xy * scale + vec2(5.3 * float(k))) / float(NOISE_TILE);
        turb += a * abs(textureLod(sampler2D(g_textures[tile], g_samplers[SAMPLER_LINEAR_REPEAT]), uv, 0.0).r);
        scale *= 2.03;
        a *= 0.5;
    }
    float slope = 1.0 - n.z + 0.12 * (turb - 0.3);
    float altitude = p.z + 80.0 * (turb - 0.3);
    // Orientation: slopes facing the sun dry out, slopes facing away keep snow.
    float facing = dot(normalize(n.xy + 1e-6), normalize(sun.xy + 1e-6)) * (1.0 - n.z) * 4.0;
    vec3 grass = vec3(0.16, 0.24, 0.08);
    vec3 dry_grass = vec3(0.34, 0.31, 0.15);
    vec3 rock = vec3(0.34, 0.31, 0.28);
    vec3 snow = vec3(0.90, 0.92, 0.95);
    vec3 c = mix(grass, dry_grass, smoothstep(0.1, 0.6, facing + 0.8 * (turb - 0.3)));
    c = mix(c, rock, smoothstep(0.22, 0.34, slope));
    float snow_line = snow_line_base - 60.0 * clamp(-facing, -1.0, 1.0);
    float dry = smoothstep(0.1, 0.6, facing + 0.8 * (turb - 0.3));
    float bare = smoothstep(0.22, 0.34, slope);
    float snowy = smoothstep(snow_line, snow_line + 40.0, altitude) * (1.0 - smoothstep(0.38, 0.55, slope));
    vec4 shares = vec4((1.0 - dry) * (1.0 - bare), dry * (1.0 - bare), bare, 0.0) * (1.0 - snowy) + vec4(0.0, 0.0, 0.0, snowy);
    type = 0u;
    for (uint k = 1u; k < 4u; ++k) {
        if (shares[k] > shares[type]) {
            type = k;
        }
    }
    return mix(c, snow, snowy);
}

TerrainShaded shade_terrain(TerrainParams p, TerrainSample s) {
    uint texturing = p.texturing_frame;
    uvec4 draw = g_texturing[texturing].draw;
    uint view = draw.x;
    bool detail = draw.y != 0u;
    uint tile = p.noise_tile;
    float d0 = p.eye.w;
    uint lighting = p.lighting;
    vec3 sun = g_lighting[lighting].f.sun.xyz;
    vec3 to_point = s.world - p.eye.xyz;
    float depth = dot(to_point, p.forward.xyz);
    TerrainShaded o;
    o.depth = depth;

    vec3 n = normalize(s.normal);
    if (detail && view == VIEW_SHADED) {
        // Octaves from the split octave up to the pixel footprint (Nyquist:
        // two pixels per wavelength) go into the normal.
        float footprint = max(depth, 1e-3) * p.forward.w;
        float o_pixel = clamp(log2(d0 / footprint), 0.0, float(MAX_DETAIL_OCTAVES));
        vec2 grad;
        detail_octaves(tile, s.world.xy, d0, p.detail_amplitude, p.detail_h, s.split, max(o_pixel, s.split), grad);
        n = normalize(n + vec3(-grad, 0.0) * n.z);
    }

    vec3 radiance;
    uint semantic = CLASS_TERRAIN;
    if (view == VIEW_SHADED) {
        vec3 a;
        uint mode = texturing != 0xffffu ? g_texturing[texturing].handles.w : TEXTURING_CLASSIC;
        vec2 extra;
        uint layer;
        if (mode == TEXTURING_ATLAS && sample_atlas(texturing, s.world.xy, a, extra, layer)) {
            // §8.2 from the atlas: colour and displacement normal of the tile.
            n = normalize(n + vec3(-extra, 0.0) * n.z);
            // A layer index beyond the tree is no layer: plain terrain.
            semantic = layer < g_texturing[texturing].grid.z ? CLASS_LAYER_BASE + layer : CLASS_TERRAIN;
        } else if (mode == TEXTURING_DIRECT) {
            // §8.2 evaluated per pixel: the reference of the atlas.
            uvec4 th = g_texturing[texturing].handles;
            vec4 sr = g_texturing[texturing].spacing_range;
            // The base surface terrain.warp draws: the resident atlas
            // blended into the streamed detail window where it is drawn.
            vec2 base_grad;
            float window;
            float h = detail_surface(g_texturing[texturing].window, th.y, g_texturing[texturing].grid.xy, sr.xy,
                                     s.world.xy, base_grad, window);
            float footprint = max(depth, 1e-3) * p.forward.w;
            vec3 maps = input_maps(g_texturing[texturing].maps, s.world.xy / g_texturing[texturing].extent.xy);
            BaseField field = BaseField(th.y, g_texturing[texturing].grid.xy, sr.xy);
            a = evaluate_layers(th.x, g_texturing[texturing].grid.z, th.z, s.world.xy, footprint, h, base_grad, sr.zw,
                                maps, field, extra, layer);
            // The layers' displacement bumps the normal on top of the mesh's.
            n = normalize(n + vec3(-extra, 0.0) * n.z);
            semantic = CLASS_LAYER_BASE + layer;
        } else if (mode != TEXTURING_ATLAS) {
            uint type;
            a = albedo(n, s.world, tile, sun, g_lighting[lighting].f.exposure.z, type);
            semantic = CLASS_LAYER_BASE + CLASSIC_LAYER[type];
        } else {
            a = albedo(n, s.world, tile, sun, g_lighting[lighting].f.exposure.z, layer);
        }
        radiance = shade_diffuse(lighting, a, s.world, n, depth, p.eye.xyz, false, o.visibility);
    } else {
        o.visibility = vec2(1.0);
        vec3 c;
        if (view == VIEW_IMPORTANCE) {
            c = ramp(sqrt(s.debug));
        } else if (view == VIEW_DENSITY_RATIO) {
            // log2 ratio: [0.5, 1] is green, lower blue, higher yellow to red.
            c = ramp(0.5 + 0.25 * log2(max(s.debug, 1e-3) / 0.7071));
        } else if (view == VIEW_SPLIT_OCTAVE) {
            c = ramp(s.split / 6.0);
        } else {
            c = vec3(0.55);
        }
        // Diagnostic colours at a daylight-like scale (the exposure is automatic).
        float light = 0.45 + 0.55 * max(dot(n, sun), 0.0);
        radiance = c * light * 3000.0;
        if (view == VIEW_WIREFRAME) {
            // Every fourth grid line, so the mesh stays legible at small image sizes.
            vec2 g = s.grid / 4.0;
            vec2 f = abs(fract(g + 0.5) - 0.5) / max(s.grid_width / 4.0, vec2(1e-6));
            float line = 1.0 - clamp(min(f.x, f.y) - 0.5, 0.0, 1.0);
            radiance = mix(radiance, vec3(0.02, 0.05, 0.12) * 3000.0, line);
        }
    }
    o.radiance = radiance;
    o.normal = n;
    o.semantic = semantic;
    return o;
}

#endif
