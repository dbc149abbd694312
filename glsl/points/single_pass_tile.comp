#version 460
// points.single_pass.merge (dissertation §10.4; ALGORITHMS.md §8): one
// workgroup per 8×8-pixel tile, one invocation per pixel. The tile's list
// is its slice of the sorted entries (glsl/include/single_pass_tiles.glsl,
// glsl/include/single_pass_radix.glsl: front to back by reach, ties in
// draw order), as points.single_pass.ranges wrote its bounds; a list the
// entry buffer's capacity cut short is dropped whole (and counted). Each
// subgroup (one SIMD row of a CPU driver: a 4×2-pixel block) walks the list
// straight from memory, no shared memory and no barrier: the entries whose
// boxes touch its blocks, each splat's set-up as points.single_pass.count
// kept it (BinnedSplat), and every pixel applies the text's fuzzy-depth
// operator to each in order, fragment (C_s, A_s, z_s) against its stored
// (C_d, A_d, z_d):
//   z_s < z_d − z_f:  C_d = C_s, A_d = A_s, z_d = z_s     (nearer: replaces)
//   z_s < z_d + z_f:  C_d = (A_d·C_d + A_s·C_s)/(A_d + A_s), A_d += A_s
//                     (same surface: blends; z_d kept)
//   otherwise:        dropped (behind),
// kept as the sums A_d·C_d, A_d (and A·normal, A·view depth) in registers.
// z is the distance along the view ray (ray–plane depth), z_f = ε·r_k with
// r_k the incoming splat's radius (camera units) and ε the visibility
// offset in splat radii (§10.2.3). A fragment the depth buffer (terrain,
// hybrid triangles) hides is dropped first, as in three-pass accumulation.
// The walk ends early once the next entry's reach (a lower bound of its
// samples' depth less its z_f, splat_reach) is at least every pixel's z_d:
// the operator drops all the later fragments (the surfaces behind). Per
// splat the same bound skips the fragments' work when no pixel of the
// subgroup both lies inside the kernel's cut-off and has z_d above the
// splat's reach (those pixels would drop the fragment: the block goes on
// walking for its other pixels, e.g. the ones no splat has covered yet).
// Finally each pixel is normalised and shaded once, exactly as
// points.normalize (glsl/include/splat_resolve.glsl): no pixel state in
// memory. The ids are those of the splat that last set z_d. Every step
// follows the sorted order, so the image is the same on every run.
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_vote : require
#define SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS_MERGE
#define SPLAT_RESOLVE_COMPUTE
#include "../include/splat_resolve.glsl"
#include "../include/single_pass_tiles.glsl"

layout(local_size_x = TILE_SIZE * TILE_SIZE) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   outputs, more = the targets written (more.zw: width, height),
//   single = (bins, entries (sorted), depth buffer (sampled; NO_HANDLE: none),
//             1: keep W where no splat is (the hybrid triangles wrote it)),
//   merge = (binned splats (BinnedSplat), -, -, -).

// A pixel's merged splats: z_d, (A_d·C_d, A_d), (A_d·n, A_d·view depth),
// the instance record of the splat that set z_d.
struct PixelState {
    float zd;
    vec4 color_weight;
    vec4 normal_depth;
    uint record;
};

// The operator on pixel state `p` for the binned splat in `slot` (reach
// `reach`, splat_reach) at the pixel centred at `centre` (view ray `ray`),
// whose depth buffer holds `stored`: the tests of splat_sample_at (kernel
// cut-off first, then the ray–plane point and the clip lines), then the
// depth buffer's, then the text's (§10.4). A pixel with z_d ≤ reach would
// drop the fragment (z − z_f ≥ reach ≥ z_d), so the subgroup skips the
// splat when no pixel is both inside the cut-off and above the reach.
void merge_splat(inout PixelState p, uint slot, float reach, vec3 ray, vec2 centre, float stored, float cutoff2) {
    uint h = pc.merge.x;
    vec4 conic = g_binned_splats[h].s[slot].conic;
    vec4 c = g_binned_splats[h].s[slot].centre;
    vec2 d = centre - c.xy;
    float r2 = conic.x * d.x * d.x + 2.0 * conic.y * d.x * d.y + conic.z * d.y * d.y;
    // Uniform: the subgroup skips the rest at once when none of its
    // pixels is inside and in front of the reach (a CPU driver then jumps
    // over it); the skipped fragments would all be dropped: exact.
    if (!subgroupAny(r2 <= cutoff2 && reach < p.zd)) {
        return;
    }
    if (r2 > cutoff2) {
        return;
    }
    vec4 normal = g_binned_splats[h].s[slot].normal;
    float t = c.w / dot(normal.xyz, ray);
    if (!(t > 0.0)) {
        return;
    }
    vec3 x = ray * t;
    vec4 position = g_binned_splats[h].s[slot].position;
    vec4 clip0 = g_binned_splats[h].s[slot].clip0;
    vec4 clip1 = g_binned_splats[h].s[slot].clip1;
    vec3 rel = x - position.xyz;
    if (dot(rel, clip0.xyz) > position.w || dot(rel, clip1.xyz) > clip0.w) {
        return;
    }
    if (depth_of(x.z) < stored) {
        return;
    }
    float z = length(x);
    float zf = c.z;
    if (!(z < p.zd + zf)) {
        return;
    }
    vec3 color = g_binned_splats[h].s[slot].color.rgb;
    float w = conic.w * gaussian(r2, cutoff2);
    vec4 color_weight = vec4(color * w, w);
    vec4 normal_depth = vec4(normal.xyz * w, -x.z * w);
    if (z < p.zd - zf) {
        p = PixelState(z, color_weight, normal_depth, floatBitsToUint(normal.w));
    } else {
        p.color_weight += color_weight;
        p.normal_depth += normal_depth;
    }
}

// The tile's slice [first, end) of the sorted entries; empty when the
// capacity cut it short (points.single_pass.scatter marked the tile and
// counted the entries past the capacity; the ones kept are counted here),
// and the longest list into the frame's counters, once per tile.
uvec2 tile_list(uint tile, uint tiles) {
    uint bins = pc.single.x;
    uint first = g_tile_bins[bins].w[tiles + STATE_WORDS + 2u * tile];
    uint end = g_tile_bins[bins].w[tiles + STATE_WORDS + 2u * tile + 1u];
    bool cut = g_tile_bins[bins].w[tile] != 0u;
    if (gl_LocalInvocationIndex == 0u && pc.handles.z != NO_HANDLE) {
        if (cut) {
            atomicAdd(g_splat_counters[pc.handles.z].tile_entries_dropped, end - first);
        }
        if (end > first) {
            atomicMax(g_splat_counters[pc.handles.z].longest_tile_list, end - first);
        }
    }
    return cut ? uvec2(first) : uvec2(first, end);
}

void main() {
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    uint tile = gl_WorkGroupID.y * grid.x + gl_WorkGroupID.x;
    uint invocation = gl_LocalInvocationIndex;
    uvec2 list = tile_list(tile, tiles);

    uint block = invocation / (BLOCK_W * BLOCK_H);
    uvec2 in_block = uvec2(invocation % BLOCK_W, (invocation / BLOCK_W) % BLOCK_H);
    uvec2 pixel = gl_WorkGroupID.xy * TILE_SIZE + uvec2(block % BLOCKS_X, block / BLOCKS_X) * uvec2(BLOCK_W, BLOCK_H) + in_block;
    bool inside = all(lessThan(pixel, pc.more.zw));
    vec2 centre = vec2(pixel) + 0.5;
    vec3 ray = pixel_ray(centre);
    float stored = 0.0;  // FAR_DEPTH (reversed depth): hides nothing
    if (inside && pc.single.z != NO_HANDLE) {
        stored = texelFetch(sampler2D(g_textures[pc.single.z], g_samplers[SAMPLER_NEAREST_CLAMP]), ivec2(pixel), 0).r;
    }
    PixelState p = PixelState(POSITIVE_INFINITY, vec4(0.0), vec4(0.0), 0u);
    float cutoff = g_point_frame[pc.handles.y].depth.w;
    float cutoff2 = cutoff * cutoff;
    // The key's reach: (bits − least) >> shift in the low depth_bits.
    uint bins = pc.single.x;
    uint least = g_tile_bins[bins].w[tiles + STATE_LEAST];
    uint shift = g_tile_bins[bins].w[tiles + STATE_SHIFT];
    uint reach_mask = (1u << g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS]) - 1u;
    // The subgroup's blocks and the greatest z_d of its pixels (0 outside
    // the view): the same in all its invocations, so they walk the list in
    // step and every load of an entry or a set-up is one load.
    uint blocks = subgroupOr(inside ? 1u << block : 0u);
    float greatest_zd = subgroupMax(inside ? p.zd : 0.0);
    // The list in runs of `run` entries, one per invocation of the subgroup
    // (at most 32: one ballot word): each tests its entry, and the ballots
    // give the run's entries whose boxes touch the subgroup's blocks, up to
    // the first whose reach (rounded down) is at least every pixel's z_d.
    uint run = min(gl_SubgroupSize, 32u);
    uint lane = gl_SubgroupInvocationID;
    uint end = blocks == 0u ? list.x : list.y;
    for (uint base = list.x; base < end; base += run) {
        uint k = base + lane;
        bool listed = lane < run && k < end;
        TileEntry e = g_tile_entries[pc.single.y].e[listed ? k : base];
        float reach = uintBitsToFloat((((e.key & reach_mask) << shift) + least));
        uint beyond = subgroupBallot(listed && !(reach < greatest_zd)).x;
        uint touching = subgroupBallot(listed && (e.blocks & blocks) != 0u).x;
        // Only the entries before the first beyond reach.
        touching &= beyond == 0u ? ~0u : (1u << findLSB(beyond)) - 1u;
        while (touching != 0u) {
            uint t = findLSB(touching);
            touching &= touching - 1u;
            TileEntry walked = g_tile_entries[pc.single.y].e[base + t];
            float walked_reach = uintBitsToFloat((((walked.key & reach_mask) << shift) + least));
            merge_splat(p, walked.slot, walked_reach, ray, centre, stored, cutoff2);
        }
        if (beyond != 0u) {
            break;
        }
        greatest_zd = subgroupMax(inside ? p.zd : 0.0);
    }
    if (!inside) {
        return;
    }
    if (p.color_weight.a > 0.0) {
        uvec2 ids = g_point_frame[pc.handles.y].instances[p.record].ids.xy;
        store_resolved(ivec2(pixel), resolve_splats(p.color_weight, p.normal_depth, centre), ids);
    } else if (pc.single.w == 0u) {
        imageStore(g_images_r32f[pc.outputs.z], ivec2(pixel), vec4(0.0));
    }
}
