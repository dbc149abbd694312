#version 460
// terrain.draw, fragment stage (dissertation §7.4.3 "Procedural Detail" and
// "Colour"; ALGORITHMS.md §3 items 6 and 8): per-pixel bump mapping with the
// detail octaves between the vertex's split octave and the pixel footprint,
// surface type from altitude, slope and orientation with turbulence-perturbed
// boundaries; lit by the frame's sun (with shadows) and sky light, seen
// through aerial perspective (§9; glsl/include/surface_lighting.glsl).
// Writes HDR radiance (absolute), view depth, the lighting AOVs, the world
// shading normal and the semantic class (src/view/aov.rs: 10 + the dominant
// surface layer; 1 in the debug views or where no atlas tile is resident).
// The debug views colour the same surface by a diagnostic instead.
#include "../include/heap.glsl"
#include "../include/terrain_detail.glsl"
#include "../include/terrain_draw.glsl"
#include "../include/bspline_height.glsl"
#include "../include/surface_layers.glsl"
#include "../include/texture_atlas.glsl"
#include "../include/surface_lighting.glsl"
#include "../include/aov.glsl"


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

void main() {
    uint texturing = pc.texturing_frame;
    uvec4 draw = g_texturing[texturing].draw;
    uint view = draw.x;
    bool detail = draw.y != 0u;
    uint tile = pc.noise_tile;
    float d0 = pc.eye.w;
    uint lighting = pc.lighting.x;
    vec3 sun = g_lighting[lighting].f.sun.xyz;
    vec3 to_point = in_world - pc.eye.xyz;
    float depth = dot(to_point, pc.forward.xyz);
    out_depth = depth;

    vec3 n = normalize(in_normal);
    if (detail && view == VIEW_SHADED) {
        // Octaves from the split octave up to the pixel footprint (Nyquist:
        // two pixels per wavelength) go into the normal.
        float footprint = max(depth, 1e-3) * pc.forward.w;
        float o_pixel = clamp(log2(d0 / footprint), 0.0, float(MAX_DETAIL_OCTAVES));
        vec2 grad;
        detail_octaves(tile, in_world.xy, d0, pc.detail_amplitude, pc.detail_h, in_split, max(o_pixel, in_split), grad);
        n = normalize(n + vec3(-grad, 0.0) * n.z);
    }

    vec3 radiance;
    uint semantic = CLASS_TERRAIN;
    if (view == VIEW_SHADED) {
        vec3 a;
        uint mode = texturing != 0xffffu ? g_texturing[texturing].handles.w : TEXTURING_CLASSIC;
        vec2 extra;
        uint layer;
        if (mode == TEXTURING_ATLAS && sample_atlas(texturing, in_world.xy, a, extra, layer)) {
            // §8.2 from the atlas: colour and displacement normal of the tile.
            n = normalize(n + vec3(-extra, 0.0) * n.z);
            // A layer index beyond the tree is no layer: plain terrain.
            semantic = layer < g_texturing[texturing].grid.z ? CLASS_LAYER_BASE + layer : CLASS_TERRAIN;
        } else if (mode == TEXTURING_DIRECT) {
            // §8.2 evaluated per pixel: the reference of the atlas.
            uvec4 th = g_texturing[texturing].handles;
            vec4 sr = g_texturing[texturing].spacing_range;
            vec2 base_grad;
            float h = bspline_height(th.y, g_texturing[texturing].grid.xy, sr.xy, in_world.xy, base_grad);
            float footprint = max(depth, 1e-3) * pc.forward.w;
            vec3 maps = input_maps(g_texturing[texturing].maps, in_world.xy / g_texturing[texturing].extent.xy);
            BaseField field = BaseField(th.y, g_texturing[texturing].grid.xy, sr.xy);
            a = evaluate_layers(th.x, g_texturing[texturing].grid.z, th.z, in_world.xy, footprint, h, base_grad, sr.zw,
                                maps, field, extra, layer);
            // The layers' displacement bumps the normal on top of the mesh's.
            n = normalize(n + vec3(-extra, 0.0) * n.z);
            semantic = CLASS_LAYER_BASE + layer;
        } else if (mode != TEXTURING_ATLAS) {
            uint type;
            a = albedo(n, in_world, tile, sun, g_lighting[lighting].f.exposure.z, type);
            semantic = CLASS_LAYER_BASE + CLASSIC_LAYER[type];
        } else {
            a = albedo(n, in_world, tile, sun, g_lighting[lighting].f.exposure.z, layer);
        }
        radiance = shade_diffuse(lighting, a, in_world, n, depth, pc.eye.xyz, out_visibility);
    } else {
        out_visibility = vec2(1.0);
        vec3 c;
        if (view == VIEW_IMPORTANCE) {
            c = ramp(sqrt(in_debug));
        } else if (view == VIEW_DENSITY_RATIO) {
            // log2 ratio: [0.5, 1] is green, lower blue, higher yellow to red.
            c = ramp(0.5 + 0.25 * log2(max(in_debug, 1e-3) / 0.7071));
        } else if (view == VIEW_SPLIT_OCTAVE) {
            c = ramp(in_split / 6.0);
        } else {
            c = vec3(0.55);
        }
        // Diagnostic colours at a daylight-like scale (the exposure is automatic).
        float light = 0.45 + 0.55 * max(dot(n, sun), 0.0);
        radiance = c * light * 3000.0;
        if (view == VIEW_WIREFRAME) {
            // Every fourth grid line, so the mesh stays legible at small image sizes.
            vec2 g = in_grid / 4.0;
            vec2 f = abs(fract(g + 0.5) - 0.5) / max(fwidth(g), vec2(1e-6));
            float line = 1.0 - clamp(min(f.x, f.y) - 0.5, 0.0, 1.0);
            radiance = mix(radiance, vec3(0.02, 0.05, 0.12) * 3000.0, line);
        }
    }
    out_color = vec4(radiance, 1.0);
    out_normal = vec4(n, 1.0);
    out_ids = uvec2(semantic, 0u);
}
