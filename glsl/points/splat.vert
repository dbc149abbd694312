#version 460
// Vertex stage of every points pass (points.visibility, points.accumulate,
// points.opaque; dissertation §10.1.6–10.1.7, §10.2.2–10.2.3, §10.3).
//
// The CPU drew only the prefix of the instance's splat list whose r_max is at
// least a lower bound of the eye distance (§10.1.7); here every splat gets the
// exact interval test r_min ≤ r < r_max with r its own eye distance (§10.1.6)
// and fails it by leaving the clip volume. Passing splats get the
// perspective-accurate EWA set-up (§10.2.2; ALGORITHMS.md §8):
//   T = K·[t_u t_v p_k] (centred on the projected centre to keep round-off
//   small), Q' = T⁻ᵀ·diag(1, 1, −F_G²)·T⁻¹, ellipse centre x_t and
//   Q''' = (F_G² / rhs)·Q'', resampling covariance V = Q'''⁻¹ + I;
// ill-conditioned splats (near edge-on, or not an ellipse) are discarded, and
// so are back-facing splats unless the frame says two-sided.
//
// Primitives (§10.3): quads by vertex pulling (6 vertices per splat, no
// duplicated splat data), instanced quads (one instance per splat) and point
// primitives (the square of the bounding box; splats larger than the
// device's largest point size are left to a quad fallback draw).
#include "../include/splat.glsl"

layout(location = 0) flat out vec4 out_conic;    // V⁻¹ (a, b, c), weight scale sqrt|Q'''⁻¹| / sqrt|V|
layout(location = 1) flat out vec4 out_centre;   // x_t (pixels), splat radius (camera units), 0
layout(location = 2) flat out vec4 out_position; // p_k (camera)
layout(location = 3) flat out vec4 out_normal;   // n (camera)
layout(location = 4) flat out vec4 out_tu;       // u = (X − p_k)·out_tu in object units
layout(location = 5) flat out vec4 out_tv;
layout(location = 6) flat out vec4 out_clip;
layout(location = 7) flat out vec4 out_color;    // linear albedo

const vec2 QUAD_CORNERS[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(-1, 1), vec2(1, -1), vec2(1, 1));

// Smallest |cos| between the view ray and the splat normal (≈ 0.6° from edge-on).
const float MIN_COS_VIEW = 0.01;

void cull() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
    gl_PointSize = 1.0;
}

void main() {
    uint primitive = pc.mode.y;
    uint splat_index;
    uint corner;
    if (primitive == SPLAT_PRIMITIVE_QUAD) {
        splat_index = uint(gl_VertexIndex) / 6u;
        corner = uint(gl_VertexIndex) % 6u;
    } else if (primitive == SPLAT_PRIMITIVE_INSTANCED) {
        splat_index = uint(gl_InstanceIndex);
        corner = uint(gl_VertexIndex);
    } else {
        splat_index = uint(gl_VertexIndex);
        corner = 0u;
    }
    uint f = pc.handles.y;
    Instance inst = g_point_frame[f].instances[pc.mode.w];
    float scale = inst.params.x;
    uint first = floatBitsToUint(inst.params.y);
    Splat s = g_splats[pc.handles.x].s[first + splat_index];

    // Interval test (§10.1.6) on the eye distance in object units.
    vec3 p = (inst.model_view * vec4(s.position_rmin.xyz, 1.0)).xyz;
    float r = length(p) / scale;
    if (!(s.position_rmin.w <= r && r < s.normal_rmax.w)) {
        cull();
        return;
    }
    bool counting = corner == 0u && pc.handles.z != NO_HANDLE;
    if (counting && pc.mode.z != SPLAT_SIZE_OVERSIZE) {
        atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
    }
    float near = g_point_frame[f].viewport.w;
    mat3 mv = mat3(inst.model_view);
    vec3 n = normalize(mv * s.normal_rmax.xyz);
    bool two_sided = g_point_frame[f].eye.w != 0.0 || inst.ids.z != 0u;
    if (-p.z < near || abs(dot(n, p)) < MIN_COS_VIEW * length(p) || (!two_sided && dot(n, p) > 0.0)) {
        cull();
        return;
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
    mat3 Ti = inverse(T);
    mat3 Qh = mat3(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -cutoff * cutoff);
    mat3 Q = transpose(Ti) * Qh * Ti;
    float a = Q[0][0], b = Q[0][1], cc = Q[1][1], d = Q[2][0], e = Q[2][1], fq = -Q[2][2];
    float delta = a * cc - b * b;
    if (!(delta > 0.0 && a > 0.0)) {
        cull();
        return;
    }
    vec2 xt = vec2(b * e - cc * d, b * d - a * e) / delta;
    float rhs = fq - d * xt.x - e * xt.y;
    if (!(rhs > 0.0)) {
        cull();
        return;
    }
    // Q''' and its inverse (the screen-space kernel covariance), in pixels².
    float k3 = cutoff * cutoff / rhs;
    mat2 q3 = mat2(a, b, b, cc) * k3;
    mat2 cov = inverse(q3);
    mat2 V = cov + mat2(1.0);
    float det_v = determinant(V);
    float det_cov = determinant(cov);
    if (!(det_v > 0.0 && det_cov > 0.0) || any(isnan(xt))) {
        cull();
        return;
    }
    mat2 Vi = inverse(V);
    vec2 half_extent = cutoff * sqrt(vec2(V[0][0], V[1][1]));
    vec2 x_t = centre + xt;

    uint size_class = pc.mode.z;
    float point_size = 2.0 * max(half_extent.x, half_extent.y) + 1.0;
    float max_point = g_point_frame[f].viewport.z;
    if ((size_class == SPLAT_SIZE_POINT && point_size > max_point) ||
        (size_class == SPLAT_SIZE_OVERSIZE && point_size <= max_point)) {
        cull();
        return;
    }
    if (counting) {
        atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
    }

    vec2 viewport = g_point_frame[f].viewport.xy;
    vec2 pixel = x_t;
    if (primitive != SPLAT_PRIMITIVE_POINT) {
        // Half a pixel more so that every pixel centre inside the ellipse is covered.
        pixel += QUAD_CORNERS[corner] * (half_extent + 0.5);
    }
    gl_Position = vec4(pixel / viewport * 2.0 - 1.0, 0.5, 1.0);
    gl_PointSize = min(ceil(point_size), max_point);

    float scale2 = scale * scale;
    out_conic = vec4(Vi[0][0], Vi[0][1], Vi[1][1], sqrt(det_cov / det_v));
    out_centre = vec4(x_t, radius * scale, 0.0);
    out_position = vec4(p, 0.0);
    out_normal = vec4(n, 0.0);
    out_tu = vec4(mv * t_o / scale2, 0.0);
    out_tv = vec4(mv * b_o / scale2, 0.0);
    out_clip = s.clip;
    out_color = vec4(unpack_srgb(s.radius_color.y), 1.0);
}
