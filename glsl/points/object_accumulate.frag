#version 460
// points.accumulate with the object-space primitives (dissertation §10.3,
// §10.2.3): the quad's own depth tested ≤ against the visibility pass;
// w = the kernel texel, additively blended as accumulate.frag does:
// w·(colour, 1) and w·(normal, view depth); the ids of the last surfel.
#include "../include/object_splat_fragment.glsl"

layout(location = 0) out vec4 out_color_weight;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out uvec2 out_ids;

void main() {
    float w = object_splat_weight();
    if (!(w > 0.0)) {
        discard;
    }
    out_color_weight = vec4(in_color.rgb * w, w);
    out_normal_depth = vec4(in_normal.xyz * w, -in_position.z * w);
    out_ids = instance_ids();
}
