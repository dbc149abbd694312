// The compute path's draw table (src/points/render/compute.rs): the
// view's splats counted over all its draws, each draw's first splat and
// instance record, ascending; `frame_splat_setup` finds a splat's draw by
// binary search and sets it up (glsl/include/splat_setup.glsl). Needs the
// push block's `draws` (SPLAT_COMPUTE).
#ifndef ALPENGLOW_SPLAT_DRAW_TABLE_GLSL
#define ALPENGLOW_SPLAT_DRAW_TABLE_GLSL

layout(set = 0, binding = 2, std430) readonly buffer SplatDraws { uvec2 d[]; } g_splat_draws[];

// The instance record and the frame index of the splat last set up.
uint splat_record;
uint splat_frame_index;

// The set-up of splat `index` of the frame (counted over the draw table).
uint frame_splat_setup(uint index, out SplatSetup v) {
    uint table = pc.draws.x;
    uint lo = 0u, hi = pc.draws.y;  // the draw is the last whose first splat ≤ index
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (g_splat_draws[table].d[mid].x <= index) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    uvec2 draw = g_splat_draws[table].d[lo];
    splat_record = draw.y;
    splat_frame_index = index;
    return splat_setup_of(draw.y, index - draw.x, v);
}

#endif
