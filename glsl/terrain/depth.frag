#version 460
// terrain.depth (the compute path, issue 28): the depth buffer from the NDC
// depth terrain.shade wrote, for the passes that depth-test against the
// terrain with the hardware (points); pixels without terrain keep the
// cleared far depth.
#include "../include/heap.glsl"

layout(push_constant) uniform Push {
    uvec4 handles;  // x: NDC depth (storage r32f), y: view depth (storage r32f)
} pc;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    // The sky's view depth is +inf: no terrain there.
    if (isinf(imageLoad(g_images_r32f[pc.handles.y], pixel).r)) {
        discard;
    }
    gl_FragDepth = imageLoad(g_images_r32f[pc.handles.x], pixel).r;
}
