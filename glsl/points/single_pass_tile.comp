#version 460
// points.single_pass.merge (dissertation §10.4; ALGORITHMS.md §8): one
// workgroup per 16×16-pixel tile, one invocation per pixel. The tile's list
// is its slice of the sorted entries (glsl/include/single_pass_tiles.glsl,
// glsl/include/single_pass_radix.glsl: front to back, ties in draw order),
// found by two binary searches for the tile's keys; a list the entry
// buffer's capacity cut short is dropped whole (and counted). It is walked
// in batches of BATCH entries: the workgroup sets the batch's splats up into
// shared memory (one invocation each, the EWA set-up of
// glsl/include/splat_setup.glsl), then every pixel applies the text's
// fuzzy-depth operator to each splat of the batch in order, fragment
// (C_s, A_s, z_s) against its stored (C_d, A_d, z_d):
//   z_s < z_d − z_f:  C_d = C_s, A_d = A_s, z_d = z_s     (nearer: replaces)
//   z_s < z_d + z_f:  C_d = (A_d·C_d + A_s·C_s)/(A_d + A_s), A_d += A_s
//                     (same surface: blends; z_d kept)
//   otherwise:        dropped (behind),
// kept as the sums A_d·C_d, A_d (and A·normal, A·view depth) in registers.
// z is the distance along the view ray (ray–plane depth), z_f = ε·r_k with
// r_k the incoming splat's radius (camera units) and ε the visibility
// offset in splat radii (§10.2.3). A fragment the depth buffer (terrain,
// hybrid triangles) hides is dropped first, as in three-pass accumulation.
// Finally each pixel is normalised and shaded once, exactly as
// points.normalize (glsl/include/splat_resolve.glsl): no pixel state in
// memory. The ids are those of the splat that last set z_d. Every step
// follows the sorted order, so the image is the same on every run.
#define SPLAT_SINGLE_PASS
#define SPLAT_RESOLVE_COMPUTE
#include "../include/splat_resolve.glsl"
#include "../include/single_pass_tiles.glsl"

#define BATCH 32u

layout(local_size_x = 256) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (splats, point frame, counter (NO_HANDLE: none), Gaussian table),
//   outputs, more = the targets written (more.zw: width, height),
//   single = (bins, entries (sorted), depth buffer (sampled; NO_HANDLE: none),
//             1: keep W where no splat is (the hybrid triangles wrote it)).

// A tile is 4×8 blocks of 4×2 pixels, and the invocations take the pixels
// block by block: eight consecutive invocations (one SIMD row of a CPU
// driver's 256-bit vectors) share a block, so they walk the same splats.
#define BLOCK_W 4u
#define BLOCK_H 2u
#define BLOCKS_X (TILE_SIZE / BLOCK_W)
#define BLOCKS (BLOCKS_X * (TILE_SIZE / BLOCK_H))

// A batch slot's set-up as the per-pixel walk reads it: the EWA set-up of
// glsl/include/splat_setup.glsl with what does not change per pixel
// computed once (the plane's offset n·p_k, z_f, the clip lines'
// directions).
struct BatchSplat {
    vec4 conic;       // V⁻¹ (a, b, c), weight scale
    vec4 centre;      // x_t (pixels), z_f = ε·r_k, n·p_k
    vec4 normal;      // n (camera), clip line 0's c0
    vec4 position;    // p_k (camera), clip line 1's c1
    vec4 tu;          // u = (X − p_k)·tu, cos θ0
    vec4 tv;          // v = (X − p_k)·tv, sin θ0
    vec4 color;       // linear albedo, cos θ1
    uvec4 ids;        // class, instance, sin θ1's bits, -
};

shared BatchSplat s_batch[BATCH];
// Per block, bit k: slot k of the batch is set up and its bounding box
// touches the block. Two sets, batches alternating: one is cleared while the
// other is read. Or-ed together, so the order of the writes does not matter.
shared uint s_touched[2][BLOCKS];

// A pixel's merged splats: z_d, (A_d·C_d, A_d), (A_d·n, A_d·view depth),
// the ids of the splat that set z_d.
struct PixelState {
    float zd;
    vec4 color_weight;
    vec4 normal_depth;
    uvec2 ids;
};

// The operator on pixel state `p` for batch slot `k` at the pixel centred
// at `centre` (view ray `ray`), whose depth buffer holds `stored`: the
// tests of splat_sample_at (kernel cut-off first, then the ray–plane
// point and the clip lines), then the depth buffer's, then the text's.
void merge_slot(inout PixelState p, uint k, vec3 ray, vec2 centre, float stored, float cutoff2) {
    vec4 conic = s_batch[k].conic;
    vec4 c = s_batch[k].centre;
    vec2 d = centre - c.xy;
    float r2 = conic.x * d.x * d.x + 2.0 * conic.y * d.x * d.y + conic.z * d.y * d.y;
    if (r2 > cutoff2) {
        return;
    }
    vec4 normal = s_batch[k].normal;
    float t = c.w / dot(normal.xyz, ray);
    if (!(t > 0.0)) {
        return;
    }
    vec3 x = ray * t;
    vec4 position = s_batch[k].position;
    vec3 rel = x - position.xyz;
    vec4 tu = s_batch[k].tu;
    vec4 tv = s_batch[k].tv;
    vec4 color = s_batch[k].color;
    uvec4 ids = s_batch[k].ids;
    vec2 uv = vec2(dot(rel, tu.xyz), dot(rel, tv.xyz));
    if (dot(uv, vec2(tu.w, tv.w)) > normal.w || dot(uv, vec2(color.w, uintBitsToFloat(ids.z))) > position.w) {
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
    float w = conic.w * gaussian(r2, cutoff2);
    vec4 color_weight = vec4(color.rgb * w, w);
    vec4 normal_depth = vec4(normal.xyz * w, -x.z * w);
    if (z < p.zd - zf) {
        p = PixelState(z, color_weight, normal_depth, ids.xy);
    } else {
        p.color_weight += color_weight;
        p.normal_depth += normal_depth;
    }
}

// Sets up sorted entry `k` into slot `slot_touched.x` of the batch
// and marks the blocks of the tile its bounding box touches in set
// `slot_touched.y` of s_touched.
void set_up_batch_slot(uint k, uvec2 slot_touched) {
    uint slot = slot_touched.x;
    TileEntry e = g_tile_entries[pc.single.y].e[k];
    SplatSetup v;
    uvec2 first, last;
    if (splat_setup_of(e.record, e.index, v) != SPLAT_SETUP_READY || !splat_pixels(v, first, last)) {
        return;
    }
    float zf = g_point_frame[pc.handles.y].depth.z * v.centre.z;
    uvec2 ids = g_point_frame[pc.handles.y].instances[e.record].ids.xy;
    s_batch[slot] = BatchSplat(v.conic, vec4(v.centre.xy, zf, dot(v.normal.xyz, v.position.xyz)),
                               vec4(v.normal.xyz, v.clip.y), vec4(v.position.xyz, v.clip.w),
                               vec4(v.tu.xyz, cos(v.clip.x)), vec4(v.tv.xyz, sin(v.clip.x)),
                               vec4(v.color.rgb, cos(v.clip.z)), uvec4(ids, floatBitsToUint(sin(v.clip.z)), 0u));
    uvec2 origin = gl_WorkGroupID.xy * TILE_SIZE;
    if (any(lessThan(last, origin)) || any(greaterThan(first, origin + TILE_SIZE - 1u))) {
        return;  // misses the tile (never, as binned)
    }
    uvec2 block = uvec2(BLOCK_W, BLOCK_H);
    uvec2 lo = (max(first, origin) - origin) / block;
    uvec2 hi = (min(last, origin + TILE_SIZE - 1u) - origin) / block;
    for (uint y = lo.y; y <= hi.y; ++y) {
        for (uint x = lo.x; x <= hi.x; ++x) {
            atomicOr(s_touched[slot_touched.y][y * BLOCKS_X + x], 1u << slot);
        }
    }
}

// The first of the `sorted` entries whose key is at least `key`.
uint lower_bound(uint key, uint sorted) {
    uint lo = 0u, hi = sorted;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (g_tile_entries[pc.single.y].e[mid].key < key) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

shared uvec2 s_list;

// The tile's slice [first, end) of the sorted entries; empty when the
// capacity cut it short (its entries are then counted as dropped).
uvec2 tile_list(uint tile, uint tiles) {
    if (gl_LocalInvocationIndex == 0u) {
        uint bins = pc.single.x;
        uint sorted = g_tile_bins[bins].w[tiles + STATE_SORTED];
        uint depth_bits = g_tile_bins[bins].w[tiles + STATE_DEPTH_BITS];
        uint first = lower_bound(tile << depth_bits, sorted);
        // The last tile index may end the key space.
        uint next = tile + 1u;
        uint end = (next >> (32u - depth_bits)) != 0u ? sorted : lower_bound(next << depth_bits, sorted);
        uint count = g_tile_bins[bins].w[tile];
        bool whole = end - first == count;
        if (!whole && pc.handles.z != NO_HANDLE) {
            atomicAdd(g_splat_counters[pc.handles.z].tile_entries_dropped, count);
        }
        s_list = whole ? uvec2(first, end) : uvec2(first);
    }
    barrier();
    return s_list;
}

void main() {
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    uint tile = gl_WorkGroupID.y * grid.x + gl_WorkGroupID.x;
    uint invocation = gl_LocalInvocationIndex;
    if (invocation < 2u * BLOCKS) {
        s_touched[invocation / BLOCKS][invocation % BLOCKS] = 0u;
    }
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
    PixelState p = PixelState(POSITIVE_INFINITY, vec4(0.0), vec4(0.0), uvec2(0u));
    float cutoff = g_point_frame[pc.handles.y].depth.w;
    float cutoff2 = cutoff * cutoff;
    for (uint b = list.x; b < list.y; b += BATCH) {
        uint set = ((b - list.x) / BATCH) & 1u;
        if (invocation < BATCH && b + invocation < list.y) {
            set_up_batch_slot(b + invocation, uvec2(invocation, set));
        }
        barrier();
        // The batch's splats whose boxes touch this pixel's block, in order.
        uint touched = inside ? s_touched[set][block] : 0u;
        while (touched != 0u) {
            uint k = findLSB(touched);
            touched &= touched - 1u;
            merge_slot(p, k, ray, centre, stored, cutoff2);
        }
        // The other set, read by the previous batch, for the next one.
        if (invocation < BLOCKS) {
            s_touched[set ^ 1u][invocation] = 0u;
        }
        barrier();
    }
    if (!inside) {
        return;
    }
    if (p.color_weight.a > 0.0) {
        store_resolved(ivec2(pixel), resolve_splats(p.color_weight, p.normal_depth, centre), p.ids);
    } else if (pc.single.w == 0u) {
        imageStore(g_images_r32f[pc.outputs.z], ivec2(pixel), vec4(0.0));
    }
}
