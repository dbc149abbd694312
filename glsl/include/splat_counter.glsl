// The points passes' per-frame counters (dissertation §10.1.7, §10.4),
// one buffer per frame slot: src/points/render/stats.rs (COUNTER_BYTES).
#ifndef ALPENGLOW_SPLAT_COUNTER_GLSL
#define ALPENGLOW_SPLAT_COUNTER_GLSL

// Per-frame counts read back into PointFrameStats (src/points/render/stats.rs):
// splats passing the interval test, splats drawn, hybrid triangles drawn, and
// of single-pass splatting (§10.4) the tile entries dropped for want of
// capacity and the longest tile list.
layout(set = 0, binding = 2, std430) buffer SplatCounter {
    uint interval_passed;
    uint drawn;
    uint triangles;
    uint tile_entries_dropped;
    uint longest_tile_list;
} g_splat_counters[];

#endif
