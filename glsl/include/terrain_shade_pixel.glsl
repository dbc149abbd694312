// terrain.shade's work on one pixel (the compute path's deferred shading,
// issue 28), shared by glsl/terrain/shade.comp and shade_splats.comp: the
// triangle terrain.raster kept, its surface sample found exactly — the
// pixel's view ray meets the triangle's plane, whose barycentrics
// interpolate the vertices as the hardware path's perspective-correct
// varyings do — and shaded once by glsl/include/terrain_shade.glsl (§7.4.3,
// §8.2, §9); the sky (glsl/include/sky_pixel.glsl) where no triangle was
// kept.
#ifndef ALPENGLOW_TERRAIN_SHADE_PIXEL_GLSL
#define ALPENGLOW_TERRAIN_SHADE_PIXEL_GLSL

#include "terrain_visibility.glsl"
#include "terrain_shade.glsl"
#include "sky_pixel.glsl"

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

// The storage targets a shaded ground pixel goes to.
struct GroundTargets {
    uvec4 images;  // radiance (rgba32f), view depth (r32f), lighting AOVs (rg32f), normal (rgba16f)
    uint ids;      // rg32ui
    uint ndc;      // the depth buffer's NDC depth (r32f; NO_DEPTH: none)
};

// Shades `pixel` of view `view` from the visibility keys `keys` over the
// grid vertices `vertices`; `surface` = lighting constants, noise tile,
// texturing constants.
void shade_ground_pixel(ComputeView view, ivec2 pixel, uvec2 grid, uvec3 surface, GroundTargets targets) {
    uint keys = grid.y;
    uint64_t key = g_visibility[keys].k[uint(pixel.y) * view.size.x + uint(pixel.x)];
    vec2 size = vec2(view.size.xy);
    vec2 ndc = (vec2(pixel) + 0.5) / size * 2.0 - 1.0;
    if (key == NO_HIT) {
        // (terrain.depth reads no NDC depth where the view depth is +inf.)
        store_sky_pixel(surface.x, ray_of(view, ndc), pixel, targets.images, targets.ids);
        return;
    }
    uint vertices = grid.x;
    uint t = uint(key & uint64_t(0xffffffffu));
    uint side = view.size.z;
    uvec3 i = grid_triangle(t, side);
    vec4 a = grid_position(vertices, i.x), b = grid_position(vertices, i.y), c = grid_position(vertices, i.z);
    vec3 p0 = a.xyz - view.eye.xyz, p1 = b.xyz - view.eye.xyz, p2 = c.xyz - view.eye.xyz;
    vec3 hit = ray_plane(ray_of(view, ndc), p0, p1, p2);
    vec3 w = vec3(1.0 - hit.x - hit.y, hit.x, hit.y);
    vec4 na = grid_normal(vertices, i.x), nb = grid_normal(vertices, i.y), nc = grid_normal(vertices, i.z);
    vec2 ga = vec2(i.x % side, i.x / side), gb = vec2(i.y % side, i.y / side), gc = vec2(i.z % side, i.z / side);
    mat3x2 grid_uv = mat3x2(ga, gb, gc);
    // The grid's screen derivatives, from the neighbouring pixels' rays on the same plane.
    vec3 hx = ray_plane(ray_of(view, ndc + vec2(2.0 / size.x, 0.0)), p0, p1, p2);
    vec3 hy = ray_plane(ray_of(view, ndc + vec2(0.0, 2.0 / size.y)), p0, p1, p2);
    vec2 g = grid_uv * w;
    vec2 dx = grid_uv * vec3(1.0 - hx.x - hx.y, hx.xy) - g;
    vec2 dy = grid_uv * vec3(1.0 - hy.x - hy.y, hy.xy) - g;

    vec3 rel = w.x * p0 + w.y * p1 + w.z * p2;
    TerrainSample s;
    s.world = view.eye.xyz + rel;
    s.normal = w.x * na.xyz + w.y * nb.xyz + w.z * nc.xyz;
    s.split = dot(w, vec3(a.w, b.w, c.w));
    s.debug = dot(w, vec3(na.w, nb.w, nc.w));
    s.grid = g;
    s.grid_width = abs(dx) + abs(dy);
    TerrainParams p = TerrainParams(view.eye, view.forward, surface.x, view.clip.z, view.clip.w, surface.y, surface.z);
    TerrainShaded o = shade_terrain(p, s);
    imageStore(g_images_rgba32f[targets.images.x], pixel, vec4(o.radiance, 1.0));
    imageStore(g_images_r32f[targets.images.y], pixel, vec4(o.depth));
    imageStore(g_images_rg32f[targets.images.z], pixel, vec4(o.visibility, 0.0, 0.0));
    imageStore(g_images_rgba16f[targets.images.w], pixel, vec4(o.normal, 1.0));
    imageStore(g_uimages_rg32ui[targets.ids], pixel, uvec4(o.semantic, 0u, 0u, 0u));
    if (targets.ndc != NO_DEPTH) {
        vec4 clip = view.view_proj_rel * vec4(rel, 1.0);
        imageStore(g_images_r32f[targets.ndc], pixel, vec4(clip.z / clip.w));
    }
}

#endif
