#version 460
// terrain.shade with the points' sums (the compute path, issue 29): the
// frame's one shading pass over the pixels. Where splats cover a pixel
// (their sums, glsl/include/splat_compute_state.glsl, hold weight: the
// points' visibility pass already tested them against the ground's keys)
// the sums are normalized and shaded as points.normalize does
// (dissertation §10.2.3 pass 3, glsl/include/splat_compute_resolve.glsl);
// elsewhere W is 0 and the ground or the sky is shaded as by
// glsl/terrain/shade.comp (§7.4.3, §8.2, §9). points.normalize is then
// not a pass of its own.
#define SPLAT_GROUND_SHADE
#include "../include/splat_compute_resolve.glsl"
#include "../include/terrain_shade_pixel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Push constants (splat.glsl's block): handles = (sums, point frame, -,
// nearest words), mode.x = last records; outputs = radiance, view depth,
// W, lighting AOVs; more = normal, ids, width, height; ground = (view
// constants, grid vertices, visibility keys, -); surface = (lighting
// constants, noise tile, texturing constants, -).

void main() {
    ComputeView view = g_compute_views[pc.ground.x].v;
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), view.size.xy))) {
        return;
    }
    if (resolve_splat_pixel(pixel, uint(pixel.y) * view.size.x + uint(pixel.x))) {
        return;
    }
    imageStore(g_images_r32f[pc.outputs.z], pixel, vec4(0.0));
    uvec4 images = uvec4(pc.outputs.x, pc.outputs.y, pc.outputs.w, pc.more.x);
    shade_ground_pixel(view, pixel, pc.ground.yz, pc.surface.xyz, GroundTargets(images, pc.more.y, NO_DEPTH));
}
