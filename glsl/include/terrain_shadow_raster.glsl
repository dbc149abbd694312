// The terrain's shadow casters in compute (issue 28; §9.5's cascaded shadow
// maps, src/terrain/shadow.rs): what terrain.shadow_clear, terrain.shadow
// and terrain.shadow_big share. The casters are the view's warped grid
// (§7.4.2), biased along the sun as glsl/lighting/shadow_terrain.vert does,
// rasterized into one cascade's quadrant of an atlas-sized buffer of depth
// bits (depth in [0, 1] orders as unsigned integers: atomicMin keeps the
// caster nearest the sun), which terrain.shadow_copy copies into the D32
// atlas. One dispatch a cascade; a triangle whose box misses the texels the
// cascade's receivers sample (src/lighting/shadows/cascades.rs, receivers)
// or its depth range is culled.
#ifndef ALPENGLOW_TERRAIN_SHADOW_RASTER_GLSL
#define ALPENGLOW_TERRAIN_SHADOW_RASTER_GLSL

#include "terrain_visibility.glsl"

layout(set = 0, binding = 2, std430) buffer ShadowDepths { uint d[]; } g_shadow_depths[];
// Per cascade: the count of triangles left to terrain.shadow_big, then the
// lists, cascade c's at c × triangles.
layout(set = 0, binding = 2, std430) buffer ShadowBig { uint count[4]; uint ids[]; } g_shadow_big[];

// src/terrain/shadow.rs, CasterRasterPush.
layout(push_constant) uniform Push {
    mat4 view_proj;   // world → atlas clip space of the cascade
    vec4 sun_texel;   // xyz: towards the sun, w: texel size (m)
    uvec4 handles;    // grid vertices, depth buffer, big-triangle lists, cascade
    uvec4 grid;       // grid side, triangles, atlas side, texels (clear)
    uvec4 receivers;  // the texels the cascade's receivers sample: first x, y, last x, y
} pc;

// Bounding boxes larger than this go to terrain.shadow_big.
const uint SHADOW_BIG_PIXELS = 64u;

// The caster triangle's state.
const int CASTER_CULLED = 0;
const int CASTER_FIXED = 1;  // set up in fixed point
const int CASTER_FLOAT = 2;  // beyond the fixed-point range: float edges

// Atlas clip position of grid vertex `i`, pushed away from the sun by
// shadow_terrain.vert's slope-scaled bias.
vec4 caster_clip(uint i) {
    vec3 sun = pc.sun_texel.xyz;
    float texel = pc.sun_texel.w;
    vec3 n = normalize(grid_normal(pc.handles.x, i).xyz);
    float c = clamp(abs(dot(n, sun)), 1e-3, 1.0);
    float tan_theta = min(sqrt(1.0 - c * c) / c, 4.0);
    precise vec3 p = grid_position(pc.handles.x, i).xyz - sun * texel * (0.5 + 0.5 * tan_theta);
    precise vec4 clip = pc.view_proj * vec4(p, 1.0);
    return clip;
}

// The first and last texel the cascade's casters write: those of its
// quadrant (column c % 2, row c / 2) its receivers can sample.
void cascade_texels(out ivec2 first, out ivec2 last) {
    first = ivec2(pc.receivers.xy);
    last = ivec2(pc.receivers.zw);
}

// Sets up caster triangle `t`: its clip positions `c`, depths `z` (in the
// order of tri.v on the fixed path), the texels to visit; CASTER_CULLED when
// it misses the cascade.
int setup_caster(uint t, out vec4 c[3], out FixedTriangle tri, out vec3 z, out ivec2 first, out ivec2 last) {
    uvec3 i = grid_triangle(t, pc.grid.x);
    c = vec4[3](caster_clip(i.x), caster_clip(i.y), caster_clip(i.z));
    z = vec3(c[0].z, c[1].z, c[2].z);
    if (max(z.x, max(z.y, z.z)) < 0.0 || min(z.x, min(z.y, z.z)) > 1.0) {
        return CASTER_CULLED;
    }
    vec2 size = vec2(pc.grid.z);
    vec2 s0 = screen_position(c[0], size), s1 = screen_position(c[1], size), s2 = screen_position(c[2], size);
    vec2 lo = min(s0, min(s1, s2)), hi = max(s0, max(s1, s2));
    ivec2 region_first, region_last;
    cascade_texels(region_first, region_last);
    // Per-cascade culling: the box misses the region (its texel centres).
    if (any(lessThan(hi, vec2(region_first) + 0.5)) || any(greaterThan(lo, vec2(region_last) + 0.5))) {
        return CASTER_CULLED;
    }
    if (any(lessThan(lo, vec2(-FIXED_LIMIT))) || any(greaterThan(hi, size + FIXED_LIMIT))) {
        first = max(ivec2(ceil(lo - 0.5)), region_first);
        last = min(ivec2(floor(hi - 0.5)), region_last);
        return any(lessThan(last, first)) ? CASTER_CULLED : CASTER_FLOAT;
    }
    if (!setup_fixed(c, size, tri)) {
        return CASTER_CULLED;
    }
    z = tri.flipped ? z.xzy : z;
    fixed_bounds(tri, ivec2(pc.grid.z), first, last);
    first = max(first, region_first);
    last = min(last, region_last);
    return any(lessThan(last, first)) ? CASTER_CULLED : CASTER_FIXED;
}

// The caster's depth at texel `pixel` on the float path (a negative value
// off the triangle): barycentrics from float edge functions.
float float_caster_depth(vec4 c[3], vec3 z, ivec2 pixel) {
    vec2 size = vec2(pc.grid.z);
    vec2 a = screen_position(c[0], size), b = screen_position(c[1], size), d = screen_position(c[2], size);
    vec2 p = vec2(pixel) + 0.5;
    float area = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
    if (area == 0.0) {
        return -1.0;
    }
    vec3 lambda = vec3((d.x - b.x) * (p.y - b.y) - (d.y - b.y) * (p.x - b.x),
                       (a.x - d.x) * (p.y - d.y) - (a.y - d.y) * (p.x - d.x),
                       (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / area;
    return any(lessThan(lambda, vec3(0.0))) ? -1.0 : dot(lambda, z);
}

// The caster's depth at texel `pixel` on the fixed path, or a negative value.
float fixed_caster_depth(FixedTriangle tri, vec3 z, ivec2 pixel) {
    vec3 lambda;
    return fixed_barycentrics(tri, pixel, lambda) ? dot(lambda, z) : -1.0;
}

// floor(n / d) and ceil(n / d) for d > 0.
int64_t floor_div(int64_t n, int64_t d) {
    return n >= 0 ? n / d : -((-n + d - 1) / d);
}
int64_t ceil_div(int64_t n, int64_t d) {
    return -floor_div(-n, d);
}

// The columns of row `y`, within [first_x, last_x], whose texel centres
// `tri` covers: exactly those fixed_barycentrics accepts (each edge
// function is linear along the row, so its tie-ruled test is a bound on x,
// solved in integers). False when none.
bool fixed_span(FixedTriangle tri, int y, int first_x, int last_x, out int x0, out int x1) {
    int64_t py = int64_t(y) * int64_t(SUBPIXELS) + int64_t(SUBPIXELS / 2.0);
    int64_t lo = int64_t(first_x), hi = int64_t(last_x);
    int64_t half_subpixel = int64_t(SUBPIXELS / 2.0);
    for (int k = 0; k < 3; ++k) {
        // Edge k runs from v[k + 1] to v[k + 2]: e = C − D·(px − a.x).
        i64vec2 a = tri.v[(k + 1) % 3], b = tri.v[(k + 2) % 3];
        int64_t d = b.y - a.y;
        int64_t r = (b.x - a.x) * (py - a.y) + tri.bias[k];
        if (d == 0) {
            if (r < 0) {
                return false;
            }
        } else if (d > 0) {
            hi = min(hi, floor_div(floor_div(r, d) + a.x - half_subpixel, int64_t(SUBPIXELS)));
        } else {
            lo = max(lo, ceil_div(ceil_div(-r, -d) + a.x - half_subpixel, int64_t(SUBPIXELS)));
        }
    }
    x0 = int(lo);
    x1 = int(hi);
    return lo <= hi;
}

// Keeps the depth nearer the sun at texel `pixel` (depths outside [0, 1]
// are clipped, as the hardware clips them).
void store_caster_depth(ivec2 pixel, float depth) {
    if (depth >= 0.0 && depth <= 1.0) {
        uint bits = depth > 0.0 ? floatBitsToUint(depth) : 0u;
        atomicMin(g_shadow_depths[pc.handles.y].d[uint(pixel.y) * pc.grid.z + uint(pixel.x)], bits);
    }
}

// Lists triangle `t` for terrain.shadow_big in the cascade's list.
void list_big_caster(uint t) {
    uint cascade = pc.handles.w;
    uint slot = atomicAdd(g_shadow_big[pc.handles.z].count[cascade], 1u);
    g_shadow_big[pc.handles.z].ids[cascade * pc.grid.y + slot] = t;
}

#endif
