#version 460
// points.single_pass.resolve (dissertation §10.4): a compute pass over the
// view's pixels that normalises and shades each pixel's merged splats
// exactly as points.normalize (glsl/include/splat_resolve.glsl); pixels no
// splat reached keep what the terrain and sky passes wrote, and W is 0
// there unless the hybrid triangles wrote it. The ids are those of the
// splat that last set the pixel's z_d (the nearest surface).
#define SPLAT_RESOLVE_COMPUTE
#include "../include/splat_resolve.glsl"
#include "../include/single_pass_state.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants (the splat passes' block, splat.glsl):
//   handles = (pixel sums (storage), point frame, 1: keep W where no splat, unused),
//   outputs, more = the targets written (more.zw: width, height).
layout(set = 0, binding = 2, std430) readonly buffer PixelSumsBuffer { PixelSums p[]; } g_pixel_sums[];

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.more.zw))) {
        return;
    }
    PixelSums s = g_pixel_sums[pc.handles.x].p[uint(p.y) * pc.more.z + uint(p.x)];
    if (!(s.color_weight.a > 0.0)) {
        if (pc.handles.z == 0u) {
            imageStore(g_images_r32f[pc.outputs.z], p, vec4(0.0));
        }
        return;
    }
    store_resolved(p, resolve_splats(s.color_weight, s.normal_depth, vec2(p) + 0.5), s.ids.xy);
}
