// Tile binning of single-pass splatting (dissertation §10.4; ALGORITHMS.md
// §8), shared by its compute passes (src/points/render/single_pass/tiles.rs):
// the screen is cut into TILE_SIZE² pixel tiles; every drawn splat is set
// up once (points.single_pass.count: the EWA set-up of splat_setup.glsl,
// kept as a BinnedSplat in its slot) and entered into the list of each tile
// its bounding box touches, as a sort key (the tile's index in the high
// bits, the splat's reach below: a lower bound of its samples' depth less
// z_f, see splat_reach) and its slot. The entries are written at positions
// that depend only on the splats' order in the draws (an exclusive prefix
// of the entry counts per workgroup of splats), then sorted by key with a
// stable LSD radix sort (glsl/include/single_pass_radix.glsl), so each
// tile's list is a slice of the sorted entries, front to back by reach,
// ties in draw order: the result does not depend on the order of the GPU's
// invocations.
//
// The bins buffer holds one word per tile (not 0: its list is cut, an entry
// fell past the entry buffer's capacity, points.single_pass.scatter), then
// the sort's state (glsl/include/single_pass_radix.glsl).
// Layouts: src/points/render/single_pass/tiles.rs.
#ifndef ALPENGLOW_SINGLE_PASS_TILES_GLSL
#define ALPENGLOW_SINGLE_PASS_TILES_GLSL

#ifndef SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS
#endif
#include "splat_setup.glsl"
#include "single_pass_radix.glsl"

#define TILE_SIZE 8u
// A tile is BLOCKS_X × BLOCKS_Y blocks of BLOCK_W × BLOCK_H pixels (one
// SIMD row of a CPU driver's 256-bit vectors; 32 blocks: one bit each in
// an entry's `blocks`).
#define BLOCK_W 4u
#define BLOCK_H 2u
#define BLOCKS_X (TILE_SIZE / BLOCK_W)
#define BLOCKS_Y (TILE_SIZE / BLOCK_H)

// A splat's slot among the binned splats: its binning workgroup's index in
// the group buffer (over the frame's draws) × 64 + its invocation.
#define BIN_WORKGROUP_SIZE 64u
// `box.x` of a splat that is not binned (outside the interval, culled or off screen).
#define NOT_BINNED 0xffffffffu

// A binned splat: the EWA set-up of glsl/include/splat_setup.glsl as the
// merge's per-pixel walk reads it (what does not change per pixel computed
// once: the plane's offset n·p_k, z_f, the clip lines as camera-space
// directions), and its pixels and reach for the scatter.
struct BinnedSplat {
    vec4 conic;     // V⁻¹ (a, b, c), weight scale
    vec4 centre;    // x_t (pixels), z_f = ε·r_k, n·p_k
    vec4 normal;    // n (camera), instance record (bits)
    vec4 position;  // p_k (camera), clip line 0's c0
    vec4 clip0;     // cos θ0·t_u + sin θ0·t_v (u·cos θ0 + v·sin θ0 = (X − p_k)·clip0), c1
    vec4 clip1;     // cos θ1·t_u + sin θ1·t_v, 0
    vec4 color;     // linear albedo, 0
    uvec4 box;      // first pixel (x | y << 16; NOT_BINNED: none), last pixel, reach's bits,
                    // the entries of the binning workgroup's earlier invocations
};
layout(set = 0, binding = 2, std430) buffer BinnedSplats { BinnedSplat s[]; } g_binned_splats[];

// Tiles per row and per column of the view.
uvec2 tile_grid() {
    uvec2 size = uvec2(g_point_frame[pc.handles.y].viewport.xy);
    return (size + TILE_SIZE - 1u) / TILE_SIZE;
}

// The pixels [first, last] whose centres the splat's bounding box (the
// three-pass mode's quad) holds; false when it holds none (off screen).
bool splat_pixels(SplatSetup v, out uvec2 first, out uvec2 last) {
    vec2 size = g_point_frame[pc.handles.y].viewport.xy;
    vec2 lo = clamp(ceil(v.centre.xy - v.half_extent - 0.5), vec2(0.0), size);
    vec2 hi = clamp(floor(v.centre.xy + v.half_extent - 0.5), vec2(-1.0), size - 1.0);
    first = uvec2(lo);
    last = uvec2(max(hi, vec2(0.0)));
    return all(greaterThanEqual(hi, lo));
}

// The splat's reach: a lower bound of the depth z (distance along the view
// ray) of its samples at the pixel centres [first, last], less z_f = `zf`.
// §10.4's operator drops a fragment with z ≥ z_d + z_f, so a splat whose
// reach is at least a pixel's z_d cannot change that pixel, and as z_d only
// decreases, neither can any splat after it in reach order. The ray
// r = K⁻¹(x, y, 1) meets the splat's plane n·X = n·p_k at
// z = |n·p_k|·|r| / |n·r|: |n·r| is at most its greatest over the box's
// corners (|affine| is convex) and |r| at least its value at the box's point
// nearest the principal point (|r|² is separable in x and y: K has no
// skew, src/points/render/gpu_layout.rs). Lessened by 2⁻¹⁶ relative for the
// round-off of the merge's own f32 steps; 0 where no bound holds.
float splat_reach(SplatSetup v, uvec2 first, uvec2 last, float zf) {
    vec2 lo = vec2(first) + 0.5, hi = vec2(last) + 0.5;
    vec3 n = v.normal.xyz;
    float most = max(max(abs(dot(n, pixel_ray(lo))), abs(dot(n, pixel_ray(hi)))),
                     max(abs(dot(n, pixel_ray(vec2(lo.x, hi.y)))), abs(dot(n, pixel_ray(vec2(hi.x, lo.y))))));
    uint f = pc.handles.y;
    vec2 principal = vec2(g_point_frame[f].k[0].z, g_point_frame[f].k[1].z) / g_point_frame[f].k[2].z;
    float least_ray = length(pixel_ray(clamp(principal, lo, hi)));
    float nearest = abs(dot(n, v.position.xyz)) * least_ray / most;
    float reach = nearest * (1.0 - 1.0 / 65536.0) - zf;
    return most > 0.0 && reach > 0.0 ? reach : 0.0;
}

// The blocks of the tile at `origin` (bit y·BLOCKS_X + x) that the pixels
// [first, last] touch. (Testing each pixel row against the cut-off ellipse
// gave tighter masks, but cost the scatter more than it saved the merge on
// lavapipe, where a block the ellipse misses costs one uniform test there.)
uint tile_blocks(uvec2 first, uvec2 last, uvec2 origin) {
    uvec2 block = uvec2(BLOCK_W, BLOCK_H);
    uvec2 lo = (max(first, origin) - origin) / block;
    uvec2 hi = (min(last, origin + TILE_SIZE - 1u) - origin) / block;
    uint columns = ((2u << hi.x) - 1u) & ~((1u << lo.x) - 1u);
    uint blocks = 0u;
    for (uint y = lo.y; y <= hi.y; ++y) {
        blocks |= columns << (y * BLOCKS_X);
    }
    return blocks;
}

// The bits of a tile index among `tiles` (at least 1).
uint tile_bits(uint tiles) {
    return tiles > 1u ? uint(findMSB(tiles - 1u)) + 1u : 1u;
}

#endif
