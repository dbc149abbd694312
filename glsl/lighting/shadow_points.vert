#version 460
// points.shadow, vertex stage (§9.5, §10.1.6): each splat of an instance's
// prefix that passes the interval test (glsl/include/shadow_points.glsl)
// becomes a quad in its tangent plane, of its disc radius, in world space,
// drawn into one cascade of the shadow atlas; six vertices per splat
// (vertex pulling). Records: src/points/render/shadow.rs.
#include "../include/shadow_points.glsl"

layout(push_constant) uniform ShadowPush {
    mat4 view_proj;   // world → atlas clip space of the cascade
    vec4 sun_texel;   // xyz: towards the sun, w: texel size (m)
    uvec4 handles;    // splats, shadow records, instance record, 0
} sp;

layout(location = 0) out vec2 out_uv;

const vec2 CORNERS[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
    uint splat_index = uint(gl_VertexIndex) / 6u;
    vec2 uv = CORNERS[uint(gl_VertexIndex) % 6u];
    out_uv = uv;
    CasterDisc d;
    if (!caster_disc(sp.handles.xy, sp.handles.z, splat_index, sp.sun_texel, d)) {
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // outside the depth range: clipped
        return;
    }
    gl_Position = sp.view_proj * vec4(d.centre + d.u * uv.x + d.v * uv.y, 1.0);
}
