// A sky pixel (§6.3; ALGORITHMS.md §6): the frame's sky model along the
// pixel's view ray plus the sun disc, in absolute units; view depth +inf;
// the lighting AOVs (1, 1), the world normal 0 and the ids (class,
// instance) sky's (0, 0; src/view/aov.rs). Shared by `sky` (a compute pass
// over every pixel) and `terrain.shade` (the compute path's deferred
// shading, which shades the pixels its visibility buffer left empty).
#ifndef ALPENGLOW_SKY_PIXEL_GLSL
#define ALPENGLOW_SKY_PIXEL_GLSL

#include "sky.glsl"
#include "aov.glsl"

// Stores the sky seen along `ray` (any length) at `pixel` of the targets:
// storage handles of radiance (rgba32f), view depth (r32f), lighting AOVs
// (rg32f), normal (rgba16f) in `images`, ids (rg32ui) in `ids`.
void store_sky_pixel(uint lighting, vec3 ray, ivec2 pixel, uvec4 images, uint ids) {
    vec3 dir = normalize(ray);
    vec3 radiance = sky_radiance(lighting, dir) + sun_disc_radiance(lighting, dir);
    imageStore(g_images_rgba32f[images.x], pixel, vec4(radiance, 1.0));
    imageStore(g_images_r32f[images.y], pixel, vec4(POSITIVE_INFINITY));
    imageStore(g_images_rg32f[images.z], pixel, vec4(1.0));
    imageStore(g_images_rgba16f[images.w], pixel, vec4(0.0));
    imageStore(g_uimages_rg32ui[ids], pixel, uvec4(CLASS_SKY, 0u, 0u, 0u));
}

#endif
