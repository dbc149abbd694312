#version 460
// terrain.shade (the compute path's deferred shading, issue 28): per pixel
// the triangle terrain.raster kept, its surface sample found exactly — the
// pixel's view ray meets the triangle's plane, whose barycentrics
// interpolate the vertices as the hardware path's perspective-correct
// varyings do — and shaded once by glsl/include/terrain_shade.glsl (§7.4.3,
// §8.2, §9). Writes radiance, view depth, the lighting AOVs, normal and ids
// where the terrain covers the pixel (the sky stays elsewhere), and the
// depth buffer's NDC depth for terrain.depth when asked. Pixels the terrain
// leaves empty get the sky (glsl/include/sky_pixel.glsl): the compute path
// has no separate sky pass.
#include "../include/terrain_visibility.glsl"
#include "../include/terrain_shade.glsl"
#include "../include/sky_pixel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // view constants, grid vertices, visibility buffer, -
    uvec4 images;   // storage: radiance (rgba32f), view depth (r32f), lighting AOVs (rg32f), normal (rgba16f)
    uvec4 more;     // storage: ids (rg32ui), NDC depth (r32f; NO_DEPTH: none)
    uvec4 surface;  // lighting constants, noise tile, texturing constants
} pc;

const uint NO_DEPTH = 0xffffffffu;

// Barycentrics (of vertices 1 and 2) and distance t of the ray 0 + t·dir on
// the plane of (p0, p1, p2).
vec3 ray_plane(vec3 dir, vec3 p0, vec3 p1, vec3 p2) {
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec3 h = cross(dir, e2);
    float a = dot(e1, h);
    if (abs(a) < 1e-20) {
        return vec3(1.0 / 3.0, 1.0 / 3.0, dot(p0, dir) / dot(dir, dir));
    }
    vec3 s = -p0;
    vec3 q = cross(s, e1);
    return vec3(dot(s, h), dot(dir, q), dot(e2, q)) / a;
}

vec3 ray_of(ComputeView view, vec2 ndc) {
    return view.ray_forward.xyz + ndc.x * view.ray_right.xyz - ndc.y * view.ray_up.xyz;
}

void main() {
    ComputeView view = g_compute_views[pc.handles.x].v;
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(pixel), view.size.xy))) {
        return;
    }
    uint64_t key = g_visibility[pc.handles.z].k[uint(pixel.y) * view.size.x + uint(pixel.x)];
    vec2 size = vec2(view.size.xy);
    vec2 ndc = (vec2(pixel) + 0.5) / size * 2.0 - 1.0;
    if (key == NO_HIT) {
        // (terrain.depth reads no NDC depth where the view depth is +inf.)
        store_sky_pixel(pc.surface.x, ray_of(view, ndc), pixel, pc.images, pc.more.x);
        return;
    }
    uint t = uint(key & uint64_t(0xffffffffu));
    uint side = view.size.z;
    uvec3 i = grid_triangle(t, side);
    vec4 a = grid_position(pc.handles.y, i.x), b = grid_position(pc.handles.y, i.y), c = grid_position(pc.handles.y, i.z);
    vec3 p0 = a.xyz - view.eye.xyz, p1 = b.xyz - view.eye.xyz, p2 = c.xyz - view.eye.xyz;
    vec3 hit = ray_plane(ray_of(view, ndc), p0, p1, p2);
    vec3 w = vec3(1.0 - hit.x - hit.y, hit.x, hit.y);
    vec4 na = grid_normal(pc.handles.y, i.x), nb = grid_normal(pc.handles.y, i.y), nc = grid_normal(pc.handles.y, i.z);
    vec2 ga = vec2(i.x % side, i.x / side), gb = vec2(i.y % side, i.y / side), gc = vec2(i.z % side, i.z / side);
    mat3x2 grid = mat3x2(ga, gb, gc);
    // The grid's screen derivatives, from the neighbouring pixels' rays on the same plane.
    vec3 hx = ray_plane(ray_of(view, ndc + vec2(2.0 / size.x, 0.0)), p0, p1, p2);
    vec3 hy = ray_plane(ray_of(view, ndc + vec2(0.0, 2.0 / size.y)), p0, p1, p2);
    vec2 g = grid * w;
    vec2 dx = grid * vec3(1.0 - hx.x - hx.y, hx.xy) - g;
    vec2 dy = grid * vec3(1.0 - hy.x - hy.y, hy.xy) - g;

    vec3 rel = w.x * p0 + w.y * p1 + w.z * p2;
    TerrainSample s;
    s.world = view.eye.xyz + rel;
    s.normal = w.x * na.xyz + w.y * nb.xyz + w.z * nc.xyz;
    s.split = dot(w, vec3(a.w, b.w, c.w));
    s.debug = dot(w, vec3(na.w, nb.w, nc.w));
    s.grid = g;
    s.grid_width = abs(dx) + abs(dy);
    TerrainParams p = TerrainParams(view.eye, view.forward, pc.surface.x, view.clip.z, view.clip.w, pc.surface.y,
                                    pc.surface.z);
    TerrainShaded o = shade_terrain(p, s);
    imageStore(g_images_rgba32f[pc.images.x], pixel, vec4(o.radiance, 1.0));
    imageStore(g_images_r32f[pc.images.y], pixel, vec4(o.depth));
    imageStore(g_images_rg32f[pc.images.z], pixel, vec4(o.visibility, 0.0, 0.0));
    imageStore(g_images_rgba16f[pc.images.w], pixel, vec4(o.normal, 1.0));
    imageStore(g_uimages_rg32ui[pc.more.x], pixel, uvec4(o.semantic, 0u, 0u, 0u));
    if (pc.more.y != NO_DEPTH) {
        vec4 clip = view.view_proj_rel * vec4(rel, 1.0);
        imageStore(g_images_r32f[pc.more.y], pixel, vec4(clip.z / clip.w));
    }
}
