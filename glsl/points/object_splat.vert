#version 460
// Vertex stage of the object-space splat primitives in every points pass
// (dissertation §10.3, Table 10.3: "quadruplication" and "instancing"), the
// counterpart of splat.vert without its screen-space EWA set-up.
//
// The splat's data arrive as vertex attributes: per vertex from the
// quadruplicated vertex buffer (the corner in radius_color.zw), or per
// instance from the splat list (the corner from gl_VertexIndex, 0..3). The
// same interval test (§10.1.6) and culls as splat.vert (near plane, edge-on,
// back faces unless two-sided) act on the splat's centre, so all four
// corners agree. The corner (u, v) ∈ {0, 1}² is placed at
// centre + R·((2u−1)·t + (2v−1)·b) in the tangent plane (R the disk radius,
// t, b the tangent frame) and projected with w = −z, so depth is the quad's
// own, i.e. the splat plane's; the visibility pass moves each corner back
// along its view ray by ε·R (§10.2.3).
#include "../include/object_splat.glsl"

layout(location = 0) in vec4 in_position_rmin;
layout(location = 1) in vec4 in_normal_rmax;
layout(location = 2) in uvec4 in_radius_color;  // radius (float bits), sRGB colour bits, corner u, v (quadruplicated)
layout(location = 3) in vec4 in_clip;

layout(location = 0) out vec3 out_position;    // camera space (not pushed back)
layout(location = 1) out vec2 out_uv;          // kernel texture coordinates in [0, 1]²
layout(location = 2) flat out vec4 out_normal; // n (camera), w: disk radius (object units)
layout(location = 3) flat out vec4 out_clip;
layout(location = 4) flat out vec4 out_color;  // linear albedo

// Corners of the instanced quad, indexed 0, 1, 2, 0, 2, 3.
const vec2 QUAD_UV[4] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 1));

// Smallest |cos| between the view ray and the splat normal, as splat.vert.
const float MIN_COS_VIEW = 0.01;

void cull() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
}

void main() {
    vec2 uv = pc.mode.y == SPLAT_PRIMITIVE_OBJECT_QUAD ? vec2(in_radius_color.zw) : QUAD_UV[gl_VertexIndex & 3];
    uint f = pc.handles.y;
    Instance inst = g_point_frame[f].instances[pc.mode.w];
    float scale = inst.params.x;

    // Interval test (§10.1.6) on the eye distance of the centre in object units.
    vec3 centre = (inst.model_view * vec4(in_position_rmin.xyz, 1.0)).xyz;
    float r = length(centre) / scale;
    if (!(in_position_rmin.w <= r && r < in_normal_rmax.w)) {
        cull();
        return;
    }
    // Corner (1, 0) lies in one triangle only, so it is shaded once per splat
    // even without a vertex cache: it counts the splat.
    bool counting = uv == vec2(1.0, 0.0) && pc.handles.z != NO_HANDLE;
    if (counting) {
        atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
    }
    float near = g_point_frame[f].viewport.w;
    mat3 mv = mat3(inst.model_view);
    vec3 n = normalize(mv * in_normal_rmax.xyz);
    bool two_sided = g_point_frame[f].eye.w != 0.0 || inst.ids.z != 0u;  // frame-wide, or this object (plants)
    if (-centre.z < near || abs(dot(n, centre)) < MIN_COS_VIEW * length(centre) ||
        (!two_sided && dot(n, centre) > 0.0)) {
        cull();
        return;
    }
    if (counting) {
        atomicAdd(g_splat_counters[pc.handles.z].drawn, 1u);
    }

    float radius = uintBitsToFloat(in_radius_color.x);
    vec3 t_o, b_o;
    tangent_frame(in_normal_rmax.xyz, t_o, b_o);
    vec2 c = 2.0 * uv - 1.0;
    vec3 corner = in_position_rmin.xyz + radius * (c.x * t_o + c.y * b_o);
    vec3 p = (inst.model_view * vec4(corner, 1.0)).xyz;
    out_position = p;
    vec4 depth = g_point_frame[f].depth;
    if (pc.mode.x == SPLAT_PASS_VISIBILITY) {
        p *= 1.0 + depth.z * radius * scale / length(p);
    }
    mat3 K = transpose(mat3(g_point_frame[f].k[0].xyz, g_point_frame[f].k[1].xyz, g_point_frame[f].k[2].xyz));
    vec3 h = K * p;  // h.z = −p.z
    vec2 viewport = g_point_frame[f].viewport.xy;
    // As hybrid.vert: NDC x, y the pixel position, NDC z = depth_of(z).
    gl_Position = vec4(h.xy / viewport * 2.0 - h.z, depth.x * p.z + depth.y, -p.z);
    out_uv = uv;
    out_normal = vec4(n, radius);
    out_clip = in_clip;
    out_color = vec4(unpack_srgb(uintBitsToFloat(in_radius_color.y)), 1.0);
}
