// Tile binning of single-pass splatting (dissertation §10.4; ALGORITHMS.md
// §8), shared by its compute passes (src/points/render/single_pass/tiles.rs):
// the screen is cut into TILE_SIZE² pixel tiles; every drawn splat is
// entered into the list of each tile its bounding box touches, as a depth
// key (the distance of the splat's centre from the eye) and a reference to
// the splat (instance record, index in the draw). The lists are sorted by
// (key, record, index), a total order, and merged front to back per pixel
// (glsl/points/single_pass_tile.comp), so the result does not depend on the
// order in which the GPU's invocations entered them.
//
// The bins buffer holds four arrays of one word per tile (T tiles):
//   [0, T)    count:  entries the splats add (points.single_pass.count)
//   [T, 2T)   offset: where the tile's list starts in the entry buffer
//   [2T, 3T)  kept:   the list's length, its count if it fits the capacity, else 0
//   [3T, 4T)  cursor: entries written so far (points.single_pass.scatter)
// Layouts: src/points/render/single_pass/tiles.rs.
#ifndef ALPENGLOW_SINGLE_PASS_TILES_GLSL
#define ALPENGLOW_SINGLE_PASS_TILES_GLSL

#ifndef SPLAT_SINGLE_PASS
#define SPLAT_SINGLE_PASS
#endif
#include "splat_setup.glsl"

#define TILE_SIZE 16u

layout(set = 0, binding = 2, std430) coherent buffer TileBins { uint w[]; } g_tile_bins[];

// One entry of a tile's list: the depth key (a positive float's bits, so
// that unsigned order is numeric order), the instance record and the
// splat's index in the draw.
struct TileEntry {
    uint key;
    uint record;
    uint index;
};
layout(set = 0, binding = 2, std430) coherent buffer TileEntries { TileEntry e[]; } g_tile_entries[];

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

// The depth key of a splat: its centre's distance from the eye.
uint splat_depth_key(SplatSetup v) {
    return floatBitsToUint(length(v.position.xyz));
}

#endif
