// What the tile generation passes share (dissertation §8.2; ALGORITHMS.md
// §4; src/texturing/generation.rs): the frame's dirty tiles as jobs, one
// thread per texel of all of them at once, and the per-texel state the
// per-layer passes carry from layer to layer in a scratch buffer.
#ifndef ALPENGLOW_TEXTURE_TILES_GLSL
#define ALPENGLOW_TEXTURE_TILES_GLSL

#include "heap.glsl"

layout(local_size_x = 64) in;

// One dirty tile (src/texturing/generation.rs, TileJob).
struct TileJob {
    vec4 world;    // xy of texel (0, 0)'s centre, texel spacing x, y (metres)
    uvec4 tile;    // first scratch texel, tile size (border included), slot x, slot y
    uvec4 images;  // colour and normal textures (storage handles), 0, 0
};

// Per texel: (modified height, displacement gradient x, y, base slope) and
// packed halves (colour rg; colour b and the dominant layer; coverage of
// levels 0–1, 2–3). The dominant layer takes the upper 16 bits of the
// second word: its index (5 bits, MAX_SURFACE_LAYERS = 32) and its share
// as an 11-bit fraction.
struct TexelState {
    vec4 surface;
    uvec4 blend;
};

layout(set = 0, binding = 2, std430) readonly buffer TileJobs { TileJob j[]; } g_tile_jobs[];
layout(set = 0, binding = 2, std430) buffer TexelStates { TexelState t[]; } g_texel_states[];

// Push constants of every texturing.* pass (TileGenerationPush); with
// TEXTURE_TILES_DETAIL_WINDOW defined (texturing.upsample, UpsamplePush) the
// detail window instead of the input maps and the extent.
layout(push_constant) uniform Push {
    uvec4 handles;        // jobs (storage), scratch (storage), layers (storage), noise tile (sampled)
    uvec4 counts;         // job count, texel count, layer index, heights (sampled)
    uvec4 grid;           // height-field columns, rows, 0, 0
    vec4 spacing_range;   // sample spacing x, y (metres), lowest and highest height
#ifdef TEXTURE_TILES_DETAIL_WINDOW
    DetailWindow window;  // texturing.upsample: the streamed detail window (detail_window.glsl)
#else
    uvec4 maps;           // input maps (sampled), w: present bits (surface_layers.glsl)
    vec4 extent;          // terrain rectangle x, y (metres), 0, 0
#endif
} pc;

// The job holding scratch texel `texel` (jobs are sorted by first texel).
uint find_job(uint texel) {
    uint lo = 0u;
    uint hi = pc.counts.x - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) / 2u;
        if (g_tile_jobs[pc.handles.x].j[mid].tile.x <= texel) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

// The texel this thread works on: false past the last one. Writes the
// job, the texel's position in its tile and its world xy.
bool tile_texel(out TileJob job, out uvec2 local, out vec2 xy) {
    uint texel = gl_GlobalInvocationID.x;
    if (texel >= pc.counts.y || pc.counts.x == 0u) {
        return false;
    }
    job = g_tile_jobs[pc.handles.x].j[find_job(texel)];
    uint i = texel - job.tile.x;
    local = uvec2(i % job.tile.y, i / job.tile.y);
    xy = job.world.xy + vec2(local) * job.world.zw;
    return true;
}

// Sample spacing of a job's texels (band limit of the layer noise).
float texel_footprint(TileJob job) {
    return max(job.world.z, job.world.w);
}

const float SHARE_STEPS = 2047.0;

TexelState pack_state(LayerState s) {
    uint dominant = min(s.dominant, 31u) | (uint(round(clamp(s.share, 0.0, 1.0) * SHARE_STEPS)) << 5u);
    uint b = (packHalf2x16(vec2(s.color.b, 0.0)) & 0xffffu) | (dominant << 16u);
    return TexelState(vec4(s.h, s.extra, s.slope),
                      uvec4(packHalf2x16(s.color.rg), b, packHalf2x16(s.coverage.xy), packHalf2x16(s.coverage.zw)));
}

LayerState unpack_state(TexelState t) {
    vec3 color = vec3(unpackHalf2x16(t.blend.x), unpackHalf2x16(t.blend.y & 0xffffu).x);
    vec4 coverage = vec4(unpackHalf2x16(t.blend.z), unpackHalf2x16(t.blend.w));
    uint dominant = t.blend.y >> 16u;
    return LayerState(t.surface.x, t.surface.yz, t.surface.w, color, coverage, dominant & 31u,
                      float(dominant >> 5u) / SHARE_STEPS);
}

#endif
