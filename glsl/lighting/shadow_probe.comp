#version 460
// shadow probe (tests, AOV checks): sun_visibility (glsl/include/shadows.glsl,
// §9.5) at a list of surface points, as the shading passes evaluate it.
#include "../include/shadows.glsl"

layout(local_size_x = 64) in;

struct ShadowProbe {
    vec4 world_depth;  // xyz: world point, w: view depth (m)
    vec4 normal;       // xyz: unit geometric normal
};

layout(set = 0, binding = 2, std430) readonly buffer ShadowProbes { ShadowProbe p[]; } g_probes[];
layout(set = 0, binding = 2, std430) writeonly buffer ShadowProbeOut { float v[]; } g_probe_out[];

layout(push_constant) uniform Push {
    uvec4 handles;  // lighting frame, probes, output (storage), probe count
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.handles.w) {
        return;
    }
    ShadowProbe probe = g_probes[pc.handles.y].p[i];
    g_probe_out[pc.handles.z].v[i] =
        sun_visibility(pc.handles.x, probe.world_depth.xyz, probe.normal.xyz, probe.world_depth.w);
}
