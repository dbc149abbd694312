#version 460
// Vertex stage of the triangles of hybrid point–polygon objects in every
// points pass (dissertation §10.1.8): vertex pulling, three vertices per
// triangle of the instance's prefix. A triangle is drawn iff r < r_max = s/ε
// (s its longest side), r a lower bound of the eye distance of all its
// points in object units (centroid distance minus the centroid's largest
// corner distance), so it covers every surfel that the floored point list
// leaves out (src/points/hybrid.rs). Back faces are culled like the splats'
// unless the frame says two-sided. Push constants as the splat passes'
// (splat.glsl), with handles.x the triangle buffer and mode.w the instance.
#include "../include/hybrid.glsl"

layout(location = 0) out vec3 out_position;      // camera space
layout(location = 1) out vec3 out_normal;        // camera space
layout(location = 2) out vec3 out_color;         // linear albedo
layout(location = 3) flat out float out_offset;  // visibility offset (camera units)

void cull() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
}

void main() {
    uint triangle_index = uint(gl_VertexIndex) / 3u;
    uint corner = uint(gl_VertexIndex) % 3u;
    uint f = pc.handles.y;
    Instance inst = g_point_frame[f].instances[pc.mode.w];
    float scale = inst.params.x;
    uint first = floatBitsToUint(inst.params.w);
    HybridTriangle t = g_hybrid_triangles[pc.handles.x].t[first + triangle_index];

    vec3 a = t.p[0].xyz, b = t.p[1].xyz, c = t.p[2].xyz;
    vec3 mid = (a + b + c) / 3.0;
    float bound = max(max(length(a - mid), length(b - mid)), length(c - mid));
    vec3 centre = (inst.model_view * vec4(mid, 1.0)).xyz;
    float r = max(length(centre) / scale - bound, 0.0);
    if (!(r < t.p[0].w)) {
        cull();
        return;
    }
    mat3 mv = mat3(inst.model_view);
    vec3 pa = (inst.model_view * vec4(a, 1.0)).xyz;
    vec3 face = cross(mv * (b - a), mv * (c - a));
    bool two_sided = g_point_frame[f].eye.w != 0.0 || inst.ids.z != 0u;
    if (!two_sided && dot(face, pa) >= 0.0) {
        cull();
        return;
    }
    if (corner == 0u && pc.handles.z != NO_HANDLE) {
        atomicAdd(g_splat_counters[pc.handles.z].triangles, 1u);
    }

    vec3 p = (inst.model_view * vec4(t.p[corner].xyz, 1.0)).xyz;
    mat3 K = transpose(mat3(g_point_frame[f].k[0].xyz, g_point_frame[f].k[1].xyz, g_point_frame[f].k[2].xyz));
    vec3 h = K * p;  // h.z = −p.z
    vec2 viewport = g_point_frame[f].viewport.xy;
    vec4 depth = g_point_frame[f].depth;
    // Clip coordinates with w = −z: NDC x, y are the pixel position, NDC z
    // the depth of depth_of(z) (splat.glsl), so triangles and splats agree.
    gl_Position = vec4((h.xy / viewport * 2.0 - h.z), depth.x * p.z + depth.y, -p.z);
    out_position = p;
    out_normal = normalize(mv * t.n[corner].xyz);
    out_color = unpack_srgb(t.n[corner].w);
    out_offset = depth.z * t.p[1].w * scale;
}
