#version 460
// points.single_pass.resolve (dissertation §10.4): a full-screen pass that
// normalises and shades each pixel's merged splats exactly as
// points.normalize (glsl/include/splat_resolve.glsl); pixels no splat
// reached keep what the terrain and sky passes wrote. The ids are those of
// the splat that last set the pixel's z_d (the nearest surface).
#include "../include/splat_resolve.glsl"
#include "../include/single_pass_state.glsl"

// Push constants (the splat passes' block, splat.glsl):
//   handles = (pixel sums (storage), point frame, unused, unused).
layout(set = 0, binding = 2, std430) readonly buffer PixelSumsBuffer { PixelSums p[]; } g_pixel_sums[];

void main() {
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    uint width = uint(g_point_frame[pc.handles.y].viewport.x);
    PixelSums s = g_pixel_sums[pc.handles.x].p[pixel.y * width + pixel.x];
    if (!(s.color_weight.a > 0.0)) {
        discard;
    }
    resolve_splats(s.color_weight, s.normal_depth);
    out_ids = s.ids.xy;
}
