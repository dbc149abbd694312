// Splats of sequential point trees (dissertation §10.1.6–10.1.7, §10.2;
// ALGORITHMS.md §7–8): the data the points passes share, the vertex-stage
// interval test and the perspective-accurate EWA set-up, and the per-fragment
// ray–plane intersection, clip lines and resampling kernel.
// Layouts match src/points/render/gpu_layout.rs.
#ifndef ALPENGLOW_SPLAT_GLSL
#define ALPENGLOW_SPLAT_GLSL

#include "heap.glsl"
#include "tangent_frame.glsl"

struct Splat {
    vec4 position_rmin;  // object-space centre, r_min
    vec4 normal_rmax;    // object-space unit normal, r_max
    vec4 radius_color;   // disk radius (object units), sRGB colour (uint bits: r | g << 8 | b << 16), view-dependent error bits, parent (spt_interval.glsl)
    vec4 clip;           // θ0, c0, θ1, c1: keep u·cos θ + v·sin θ ≤ c (c = FLT_MAX: no line)
};

struct Instance {
    mat4 model_view;     // object → camera (rigid motion × uniform scale), computed in f64
    vec4 params;         // scale, first splat (bits), prefix length (bits), first hybrid triangle (bits)
    uvec4 ids;           // semantic class, instance id (src/view/aov.rs), 1 = two-sided object, 0
};

layout(set = 0, binding = 2, std430) readonly buffer Splats { Splat s[]; } g_splats[];
layout(set = 0, binding = 2, std430) readonly buffer PointFrame {
    vec4 k[3];                // rows of K: camera → homogeneous pixel coordinates
    vec4 k_inv[3];            // rows of K⁻¹
    vec4 depth;               // P22, P32 (camera z → depth), visibility offset (× splat radius), cutoff F_G
    vec4 viewport;            // width, height, largest point size, near
    uvec4 lighting;           // x: the view's LightingFrame (storage), y: 1 shaded, 0 unlit, z: splat kernel (SPLAT_KERNEL_*), w: interval test (SPT_ERROR_*)
    vec4 camera_to_world[3];  // rows of the camera → world rotation
    vec4 eye;                 // world eye position, w: 1 = two-sided splats, 0 = back faces culled
    Instance instances[];
} g_point_frame[];
#include "splat_counter.glsl"
layout(set = 0, binding = 2, std430) readonly buffer GaussianTable { float g[]; } g_gaussian[];

#define SPLAT_PASS_VISIBILITY 0u
#define SPLAT_PASS_ACCUMULATE 1u
#define SPLAT_PASS_OPAQUE 2u

#define SPLAT_PRIMITIVE_QUAD 0u
#define SPLAT_PRIMITIVE_INSTANCED 1u
#define SPLAT_PRIMITIVE_POINT 2u

#define SPLAT_SIZE_ANY 0u
#define SPLAT_SIZE_POINT 1u      // only splats that fit the largest point size
#define SPLAT_SIZE_OVERSIZE 2u   // only splats that do not (the point fallback)

#define NO_HANDLE 0xffffffffu
#define GAUSSIAN_TABLE_SIZE 256

layout(push_constant) uniform Push {
    uvec4 handles;  // splats, point frame, drawn counter (NO_HANDLE: none), Gaussian table
    uvec4 mode;     // pass, primitive, size class, instance index
#ifdef SPLAT_RESOLVE_COMPUTE
    uvec4 outputs;  // storage: radiance (rgba32f), view depth (r32f), W (r32f), lighting AOVs (rg32f)
    uvec4 more;     // storage: normal (rgba16f), ids (rg32ui); width, height
#endif
#ifdef SPLAT_GROUND_SHADE
    uvec4 ground;   // terrain.shade with the points' sums: compute view constants, grid vertices, visibility keys, -
    uvec4 surface;  // lighting constants, noise tile, texturing constants, -
#endif
#ifdef SPLAT_COMPUTE
    uvec4 raster;   // compute three-pass (glsl/include/splat_compute.glsl): nearest words, sums, last records, splats of the frame
    uvec4 draws;    // the draw table (storage: first splat, instance record per draw), draws, 0, 0
#endif
#ifdef SPLAT_SINGLE_PASS
    uvec4 single;   // single-pass (§10.4): interlock: pixel words, pixel sums, depth buffer (sampled; NO_HANDLE: cleared), splats of the draw;
                    // tiles: see glsl/include/single_pass_tiles.glsl
#endif
#ifdef SPLAT_SINGLE_PASS_BIN
    uvec4 bin;      // single-pass tiles' binning (glsl/points/single_pass_bin.comp): group buffer, the draw's first group, binned splats, -
#endif
#ifdef SPLAT_SINGLE_PASS_MERGE
    uvec4 merge;    // single-pass tiles' merge (glsl/points/single_pass_tile.comp): binned splats, -, -, -
#endif
} pc;


#include "srgb.glsl"

// Linear colour of an sRGB8 triple packed as uint bits r | g << 8 | b << 16 in a float.
vec3 unpack_srgb(float bits) {
    uint rgb = floatBitsToUint(bits);
    return srgb_to_linear(vec3(float(rgb & 0xffu), float((rgb >> 8) & 0xffu), float((rgb >> 16) & 0xffu)) / 255.0);
}

// exp(−r²/2) for r² in [0, F_G²] from the lookup table (§10.2: "Gaussian from
// a lookup table"), linearly interpolated; `cutoff2` = F_G².
float gaussian(float r2, float cutoff2) {
    float x = clamp(r2 / cutoff2, 0.0, 1.0) * float(GAUSSIAN_TABLE_SIZE - 1);
    int i = min(int(x), GAUSSIAN_TABLE_SIZE - 2);
    float f = x - float(i);
    return mix(g_gaussian[pc.handles.w].g[i], g_gaussian[pc.handles.w].g[i + 1], f);
}

// Homogeneous pixel coordinates → camera-space ray direction.
vec3 pixel_ray(vec2 pixel) {
    vec3 x = vec3(pixel, 1.0);
    uint f = pc.handles.y;
    return vec3(dot(g_point_frame[f].k_inv[0].xyz, x), dot(g_point_frame[f].k_inv[1].xyz, x),
                dot(g_point_frame[f].k_inv[2].xyz, x));
}

// Class and instance id of the draw's instance (the ids AOV).
uvec2 instance_ids() {
    return g_point_frame[pc.handles.y].instances[pc.mode.w].ids.xy;
}

// Depth-buffer value of a camera-space z (< 0).
float depth_of(float z) {
    vec4 d = g_point_frame[pc.handles.y].depth;
    return clamp((d.x * z + d.y) / -z, 0.0, 1.0);
}

#endif
