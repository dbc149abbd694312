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
layout(location = 0) out vec4 out_radiance;
layout(location = 1) out float out_view_depth;
layout(location = 2) out float out_weight;
layout(location = 3) out vec2 out_visibility;
layout(location = 4) out vec4 out_normal;
layout(location = 5) out uvec2 out_ids;

layout(set = 0, binding = 2, std430) readonly buffer PixelSumsBuffer { PixelSums p[]; } g_pixel_sums[];

void main() {
    uvec2 pixel = uvec2(gl_FragCoord.xy);
    uint width = uint(g_point_frame[pc.handles.y].viewport.x);
    PixelSums s = g_pixel_sums[pc.handles.x].p[pixel.y * width + pixel.x];
    if (!(s.color_weight.a > 0.0)) {
        discard;
    }
    ResolvedSplats r = resolve_splats(s.color_weight, s.normal_depth, gl_FragCoord.xy);
    out_radiance = r.radiance;
    out_view_depth = r.view_depth;
    out_weight = r.weight;
    out_visibility = r.visibility;
    out_normal = r.normal;
    out_ids = s.ids.xy;
}
