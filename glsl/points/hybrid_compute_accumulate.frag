#version 460
// points.accumulate.triangles on the compute path (dissertation §10.1.8,
// §10.2.3): a triangle fragment at or in front of the pixel's nearest
// pushed-back depth adds weight 1 (a splat's kernel peak) of its colour,
// normal and view depth to the pixel's fixed-point sums
// (glsl/include/splat_compute_state.glsl), as the hardware path's
// hybrid_accumulate.frag adds them to its float targets.
#define SPLAT_COMPUTE
#include "../include/splat_compute_state.glsl"
#include "../include/hybrid_fragment.glsl"

void main() {
    uint p = uint(gl_FragCoord.y) * uint(g_point_frame[pc.handles.y].viewport.x) + uint(gl_FragCoord.x);
    float nearest = splat_nearest_depth(pc.raster.x, p);
    if (gl_FragCoord.z < nearest) {
        return;
    }
    float relative = -in_position.z / splat_view_depth(nearest, g_point_frame[pc.handles.y].depth.xy);
    splat_accumulate(pc.raster.yz, p, 1.0, in_color, normalize(in_normal), relative, pc.mode.w);
}
