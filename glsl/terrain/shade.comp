#version 460
// terrain.shade (the compute path's deferred shading, issue 28): every
// pixel of the view shaded once from the visibility buffer terrain.raster
// filled (glsl/include/terrain_shade_pixel.glsl: the terrain where a
// triangle covers the pixel, the sky elsewhere — the compute path has no
// separate sky pass). Writes radiance, view depth, the lighting AOVs,
// normal and ids, and the depth buffer's NDC depth for terrain.depth when
// asked. glsl/terrain/shade_splats.comp is this pass with the points' sums.
#include "../include/terrain_shade_pixel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // view constants, grid vertices, visibility buffer, -
    uvec4 images;   // storage: radiance (rgba32f), view depth (r32f), lighting AOVs (rg32f), normal (rgba16f)
    uvec4 more;     // storage: ids (rg32ui), NDC depth (r32f; NO_DEPTH: none)
    uvec4 surface;  // lighting constants, noise tile, texturing constants
} pc;

void main() {
    ComputeView view = g_compute_views[pc.handles.x].v;
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), view.size.xy))) {
        return;
    }
    shade_ground_pixel(view, pixel, pc.handles.yz, pc.surface.xyz, GroundTargets(pc.images, pc.more.x, pc.more.y));
}
