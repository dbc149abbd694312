#version 460
// points.visibility.triangles on the compute path (dissertation §10.1.8,
// §10.2.3): the hybrid triangles' depth pushed back by the surfels' offset,
// raised into the pixels' nearest words with the instance record as the
// splats' compute pass does (glsl/include/splat_compute_state.glsl), so
// splats of the same surface next to a triangle blend with it. No
// attachment is written: the depth buffer's depth is already in the words.
#define SPLAT_COMPUTE
#include "../include/splat_compute_state.glsl"
#include "../include/hybrid_fragment.glsl"

void main() {
    vec3 pushed = in_position * (1.0 + in_offset / length(in_position));
    uint p = uint(gl_FragCoord.y) * uint(g_point_frame[pc.handles.y].viewport.x) + uint(gl_FragCoord.x);
    splat_raise_nearest(pc.raster.x, p, depth_of(pushed.z), pc.mode.w);
}
