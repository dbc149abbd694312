// Tile binning of single-pass splatting (dissertation §10.4; ALGORITHMS.md
// §8), shared by its compute passes (src/points/render/single_pass/tiles.rs):
// the screen is cut into TILE_SIZE² pixel tiles; every drawn splat is
// entered into the list of each tile its bounding box touches, as a sort
// key (the tile's index in the high bits, the splat centre's distance from
// the eye below) and a reference to the splat (instance record, index in
// the draw). The entries are written at positions that depend only on the
// splats' order in the draws (an exclusive prefix of the entry counts per
// workgroup of splats), then sorted by key with a stable LSD radix sort
// (glsl/include/single_pass_radix.glsl), so each tile's list is a slice of
// the sorted entries, front to back, ties in draw order: the result does
// not depend on the order of the GPU's invocations.
//
// The bins buffer holds one word per tile (its count of entries, from
// points.single_pass.count), then the sort's state
// (glsl/include/single_pass_radix.glsl).
// Layouts: src/points/render/single_pass/tiles.rs.
#ifndef ALPENGLOW_SINGLE_PASS_TILES_GLSL
#define ALPENGLOW_SINGLE_PASS_TILES_GLSL

#ifndef SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS
#endif
#include "splat_setup.glsl"
#include "single_pass_radix.glsl"

#define TILE_SIZE 16u

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

// The tiles [lo, hi) whose pixel centres the splat's bounding box may
// hold; false when it holds none (off screen).
bool splat_tiles(SplatSetup v, out uvec2 lo, out uvec2 hi) {
    uvec2 first, last;
    bool any_pixel = splat_pixels(v, first, last);
    lo = first / TILE_SIZE;
    hi = last / TILE_SIZE + 1u;
    return any_pixel;
}

// The depth of a splat: its centre's distance from the eye, as the bits of
// a positive float (unsigned order is numeric order).
uint splat_depth_bits(SplatSetup v) {
    return floatBitsToUint(length(v.position.xyz));
}

// The bits of a tile index among `tiles` (at least 1).
uint tile_bits(uint tiles) {
    return tiles > 1u ? uint(findMSB(tiles - 1u)) + 1u : 1u;
}

#endif
