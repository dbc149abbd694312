#version 460
// points.accumulate on the compute path (dissertation §10.2.3, Table 10.1
// pass 2): fragments at or in front of the pixel's nearest pushed-back depth
// (the hardware pass's ≤ test without depth writes) add w·(colour, 1) and
// w·(normal, view depth relative to the nearest) to the pixel's fixed-point sums with 64-bit integer
// atomics (glsl/include/splat_compute_state.glsl): order-independent, so the
// frame is the same to the byte on every run.
#include "../include/splat_compute.glsl"

void splat_pixel(SplatSetup v, uvec2 pixel) {
    SplatSample s;
    if (!splat_sample_at(vec2(pixel) + 0.5, v, s)) {
        return;
    }
    uint p = splat_pixel_index(pixel);
    float nearest = splat_nearest_depth(pc.raster.x, p);
    if (depth_of(s.position.z) < nearest) {
        return;
    }
    float relative = -s.position.z / splat_view_depth(nearest, g_point_frame[pc.handles.y].depth.xy);
    splat_accumulate(pc.raster.yz, p, s.weight, v.color.rgb, v.normal.xyz, relative, splat_record);
}
