#version 460
// points.accumulate (dissertation §10.2.3, Table 10.1 pass 2): depth test
// against the visibility pass (≤, no depth writes), additive blending of
// w·(colour, 1) and w·(normal, view depth) into float targets; the ids
// (class, instance) of the last surfel accumulated, never blended (integer
// target): points.normalize falls back to them where the visibility pass's
// pushed-back depth lost against the terrain.
#include "../include/splat_fragment.glsl"

layout(location = 0) out vec4 out_color_weight;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out uvec2 out_ids;

void main() {
    SplatSample s;
    if (!splat_sample(s)) {
        discard;
    }
    gl_FragDepth = depth_of(s.position.z);
    float w = s.weight;
    out_color_weight = vec4(in_color.rgb * w, w);
    out_normal_depth = vec4(in_normal.xyz * w, -s.position.z * w);
    out_ids = instance_ids();
}
