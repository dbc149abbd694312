#version 460
// points.visibility on the compute path (dissertation §10.2.3, Table 10.1
// pass 1): each fragment's ray–plane depth pushed back along the view ray by
// ε (a fraction of the splat radius), raised into the pixel's nearest word
// with the splat's instance record (glsl/include/splat_compute_state.glsl):
// the depth test of the hardware pass, and the winner's ids without a race.
#include "../include/splat_compute.glsl"

void splat_pixel(SplatSetup v, uvec2 pixel) {
    SplatSample s;
    if (!splat_sample_at(vec2(pixel) + 0.5, v, s)) {
        return;
    }
    float offset = g_point_frame[pc.handles.y].depth.z * v.centre.z;
    vec3 pushed = s.position * (1.0 + offset / length(s.position));
    splat_raise_nearest(pc.raster.x, splat_pixel_index(pixel), depth_of(pushed.z), splat_record);
}
