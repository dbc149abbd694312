#version 460
// Vertex stage of every points pass (points.visibility, points.accumulate,
// points.opaque, points.single_pass.interlock; dissertation §10.1.6–10.1.7,
// §10.2.2–10.2.3, §10.3).
//
// The CPU drew only the prefix of the instance's splat list whose r_max is at
// least a lower bound of the eye distance (§10.1.7); here every splat gets the
// exact interval test and the perspective-accurate EWA set-up
// (glsl/include/splat_setup.glsl); splats that fail either leave the clip volume.
//
// Primitives (§10.3): quads by vertex pulling (6 vertices per splat, no
// duplicated splat data), instanced quads (one instance per splat) and point
// primitives (the square of the bounding box; splats larger than the
// device's largest point size are left to a quad fallback draw).
#include "../include/splat_setup.glsl"

layout(location = 0) flat out vec4 out_conic;    // V⁻¹ (a, b, c), weight scale sqrt|Q'''⁻¹| / sqrt|V|
layout(location = 1) flat out vec4 out_centre;   // x_t (pixels), splat radius (camera units), 0
layout(location = 2) flat out vec4 out_position; // p_k (camera)
layout(location = 3) flat out vec4 out_normal;   // n (camera)
layout(location = 4) flat out vec4 out_tu;       // u = (X − p_k)·out_tu in object units
layout(location = 5) flat out vec4 out_tv;
layout(location = 6) flat out vec4 out_clip;
layout(location = 7) flat out vec4 out_color;    // linear albedo

const vec2 QUAD_CORNERS[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(-1, 1), vec2(1, -1), vec2(1, 1));

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
    SplatSetup v;
    uint setup = splat_setup(splat_index, v);
    bool counting = corner == 0u && pc.handles.z != NO_HANDLE;
    if (counting && setup != SPLAT_SETUP_OUTSIDE_INTERVAL && pc.mode.z != SPLAT_SIZE_OVERSIZE) {
        atomicAdd(g_splat_counters[pc.handles.z].interval_passed, 1u);
    }
    if (setup != SPLAT_SETUP_READY) {
        cull();
        return;
    }

    uint f = pc.handles.y;
    uint size_class = pc.mode.z;
    float point_size = 2.0 * max(v.half_extent.x, v.half_extent.y) + 1.0;
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
    vec2 pixel = v.centre.xy;
    if (primitive != SPLAT_PRIMITIVE_POINT) {
        // Half a pixel more so that every pixel centre inside the ellipse is covered.
        pixel += QUAD_CORNERS[corner] * (v.half_extent + 0.5);
    }
    gl_Position = vec4(pixel / viewport * 2.0 - 1.0, 0.5, 1.0);
    gl_PointSize = min(ceil(point_size), max_point);

    out_conic = v.conic;
    out_centre = v.centre;
    out_position = v.position;
    out_normal = v.normal;
    out_tu = v.tu;
    out_tv = v.tv;
    out_clip = v.clip;
    out_color = v.color;
}
