// The per-splat and per-pixel halves of perspective-accurate EWA splatting
// (dissertation §10.1.6, §10.2.2–10.2.4; ALGORITHMS.md §8), shared by the
// vertex/fragment stages of the three-pass mode (glsl/points/splat.vert,
// glsl/include/splat_fragment.glsl) and by single-pass splatting (§10.4,
// glsl/include/single_pass_tiles.glsl, glsl/points/single_pass_tile.comp;
// and the compute path's three passes, glsl/include/splat_compute.glsl),
// so every mode draws the same kernels.
//
// splat_setup: the exact interval test r_min ≤ r < r_max with r the splat's
// eye distance (§10.1.6; or the view-dependent one, glsl/include/spt_interval.glsl), culling (near plane, near edge-on, back faces unless
// two-sided) and the EWA set-up (§10.2.2):
//   T = K·[t_u t_v p_k] (centred on the projected centre to keep round-off
//   small), Q' = T⁻ᵀ·diag(1, 1, −F_G²)·T⁻¹, ellipse centre x_t and
//   Q''' = (F_G² / rhs)·Q'', resampling covariance V = Q'''⁻¹ + I;
// ill-conditioned splats (near edge-on, or not an ellipse) are culled.
// With the affine kernel (the frame's lighting.z = SPLAT_KERNEL_AFFINE; the
// approximation of Zwicker et al. 2001 that §10.2 and Figs. 10.15–10.17 set
// against the perspective-accurate one) the object-space Gaussian is instead
// mapped through the Jacobian J of the projection at the splat centre:
// V = J·[t_u t_v]·[t_u t_v]ᵀ·Jᵀ + I, centred on the projected centre; the
// ray–plane depth and clip lines below stay the same for both kernels.
//
// splat_sample_at: the view ray through a pixel meets the splat's plane
// (ray–plane depth), the tangent coordinates of that point are tested
// against the clip lines, and the screen-space resampling kernel gives the weight.
#ifndef ALPENGLOW_SPLAT_SETUP_GLSL
#define ALPENGLOW_SPLAT_SETUP_GLSL

#include "splat.glsl"
#include "spt_interval.glsl"

// What the per-pixel kernel needs of a splat (the three-pass mode passes it
// as flat varyings).
struct SplatSetup {
    vec4 conic;     // V⁻¹ (a, b, c), weight scale sqrt|Q'''⁻¹| / sqrt|V|
    vec4 centre;    // x_t (pixels), splat radius (camera units), 0
    vec4 position;  // p_k (camera)
    vec4 normal;    // n (camera)
    vec4 tu;        // u = (X − p_k)·tu in object units
    vec4 tv;
    vec4 clip;      // θ0, c0, θ1, c1 (object units)
    vec4 color;     // linear albedo
    vec2 half_extent;  // half the bounding box of the cut-off ellipse (pixels)
};

#define SPLAT_SETUP_OUTSIDE_INTERVAL 0u  // fails the interval test
#define SPLAT_SETUP_CULLED 1u            // passes it, but is culled
#define SPLAT_SETUP_READY 2u             // drawn

// Smallest |cos| between the view ray and the splat normal (≈ 0.6° from edge-on).
const float MIN_COS_VIEW = 0.01;

#define SPLAT_KERNEL_PERSPECTIVE 0u
#define SPLAT_KERNEL_AFFINE 1u

// The perspective-accurate screen ellipse of the (scale-normalised) T
// (§10.2.2): its centre offset x_t and the kernel covariance Q'''⁻¹ in
// pixels²; false when it is no ellipse.
bool perspective_conic(mat3 T, float cutoff, out vec2 xt, out mat2 cov) {
    xt = vec2(0.0);
    cov = mat2(0.0);
    mat3 Ti = inverse(T);
    mat3 Qh = mat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -cutoff * cutoff);
    mat3 Q = transpose(Ti) * Qh * Ti;
    float a = Q[0][0], b = Q[0][1], cc = Q[1][1], d = Q[2][0], e = Q[2][1], fq = -Q[2][2];
    float delta = a * cc - b * b;
    if (!(delta > 0.0 && a > 0.0)) {
        return false;
    }
    xt = vec2(b * e - cc * d, b * d - a * e) / delta;
    float rhs = fq - d * xt.x - e * xt.y;
    if (!(rhs > 0.0)) {
        return false;
    }
    // Q''' and its inverse (the screen-space kernel covariance), in pixels².
    float k3 = cutoff * cutoff / rhs;
    cov = inverse(mat2(a, b, b, cc) * k3);
    return true;
}

// The set-up of splat `splat_index` of instance record `record`.
uint splat_setup_of(uint record, uint splat_index, out SplatSetup o) {
    uint f = pc.handles.y;
    Instance inst = g_point_frame[f].instances[record];
    float scale = inst.params.x;
    uint first = floatBitsToUint(inst.params.y);
    Splat s = g_splats[pc.handles.x].s[first + splat_index];

    // Interval test (§10.1.6; view-dependent: §10.1.7) on the eye distance in object units.
    vec3 p = (inst.model_view * vec4(s.position_rmin.xyz, 1.0)).xyz;
    float r = length(p) / scale;
    if (!spt_interval(pc.handles.x, first + splat_index, r, g_point_frame[f].lighting.w, inst.model_view, vec3(0.0))) {
        return SPLAT_SETUP_OUTSIDE_INTERVAL;
    }
    float near = g_point_frame[f].viewport.w;
    mat3 mv = mat3(inst.model_view);
    vec3 n = normalize(mv * s.normal_rmax.xyz);
    bool two_sided = g_point_frame[f].eye.w != 0.0 || inst.ids.z != 0u;  // frame-wide, or this object (plants)
    if (-p.z < near || abs(dot(n, p)) < MIN_COS_VIEW * length(p) || (!two_sided && dot(n, p) > 0.0)) {
        return SPLAT_SETUP_CULLED;
    }

    // EWA set-up (§10.2.2).
    float cutoff = g_point_frame[f].depth.w;
    float radius = s.radius_color.x;
    vec3 t_o, b_o;
    tangent_frame(s.normal_rmax.xyz, t_o, b_o);
    vec3 tu = mv * (t_o * (radius / cutoff));  // length σ (camera units)
    vec3 tv = mv * (b_o * (radius / cutoff));
    mat3 K = transpose(mat3(g_point_frame[f].k[0].xyz, g_point_frame[f].k[1].xyz, g_point_frame[f].k[2].xyz));
    vec3 c = K * p;
    vec2 centre = c.xy / c.z;
    // K' = [1 0 −cx; 0 1 −cy; 0 0 1]·K maps p to (0, 0, c.z).
    mat3 recentre = mat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, -centre.x, -centre.y, 1.0);
    mat3 T = recentre * K * mat3(tu, tv, p);
    // Q' is homogeneous in T: normalise T's scale before inverting.
    float t_scale = max(max(length(T[0]), length(T[1])), abs(T[2].z));
    T /= t_scale;
    vec2 xt;
    mat2 cov;
    if (g_point_frame[f].lighting.z == SPLAT_KERNEL_AFFINE) {
        // The Jacobian of the (recentred) projection at p_k is the top rows
        // of T's recentred K over c.z; the tangent axes have length σ.
        mat2 m = mat2(T[0].xy, T[1].xy) / T[2].z;
        cov = m * transpose(m);
        xt = vec2(0.0);
    } else if (!perspective_conic(T, cutoff, xt, cov)) {
        return SPLAT_SETUP_CULLED;
    }
    mat2 V = cov + mat2(1.0);
    float det_v = determinant(V);
    float det_cov = determinant(cov);
    if (!(det_v > 0.0 && det_cov > 0.0) || any(isnan(xt))) {
        return SPLAT_SETUP_CULLED;
    }
    mat2 Vi = inverse(V);
    float scale2 = scale * scale;
    o.half_extent = cutoff * sqrt(vec2(V[0][0], V[1][1]));
    o.conic = vec4(Vi[0][0], Vi[0][1], Vi[1][1], sqrt(det_cov / det_v));
    o.centre = vec4(centre + xt, radius * scale, 0.0);
    o.position = vec4(p, 0.0);
    o.normal = vec4(n, 0.0);
    o.tu = vec4(mv * t_o / scale2, 0.0);
    o.tv = vec4(mv * b_o / scale2, 0.0);
    o.clip = s.clip;
    o.color = vec4(unpack_srgb(s.radius_color.y), 1.0);
    return SPLAT_SETUP_READY;
}

// The set-up of splat `splat_index` of the draw's instance (pc.mode.w).
uint splat_setup(uint splat_index, out SplatSetup o) {
    return splat_setup_of(pc.mode.w, splat_index, o);
}

struct SplatSample {
    vec3 position;  // camera-space point of the splat plane seen through the pixel
    float weight;   // EWA resampling weight
    float r2;       // r² of the resampling kernel (≤ F_G²)
    vec2 uv;        // tangent coordinates (object units)
};

// The splat `v` at the pixel position `pixel` (a pixel centre); false when
// the pixel is outside the splat (kernel cut-off, clip lines, or the plane
// is behind the eye).
bool splat_sample_at(vec2 pixel, SplatSetup v, out SplatSample s) {
    vec2 d = pixel - v.centre.xy;
    float r2 = v.conic.x * d.x * d.x + 2.0 * v.conic.y * d.x * d.y + v.conic.z * d.y * d.y;
    float cutoff = g_point_frame[pc.handles.y].depth.w;
    if (r2 > cutoff * cutoff) {
        return false;
    }
    vec3 ray = pixel_ray(pixel);
    float denom = dot(v.normal.xyz, ray);
    float t = dot(v.normal.xyz, v.position.xyz) / denom;
    if (!(t > 0.0)) {
        return false;
    }
    vec3 x = ray * t;
    vec3 rel = x - v.position.xyz;
    vec2 uv = vec2(dot(rel, v.tu.xyz), dot(rel, v.tv.xyz));
    if (dot(uv, vec2(cos(v.clip.x), sin(v.clip.x))) > v.clip.y ||
        dot(uv, vec2(cos(v.clip.z), sin(v.clip.z))) > v.clip.w) {
        return false;
    }
    s.position = x;
    s.r2 = r2;
    s.weight = v.conic.w * gaussian(r2, cutoff * cutoff);
    s.uv = uv;
    return true;
}

#endif
