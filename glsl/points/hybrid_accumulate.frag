#version 460
// points.accumulate, hybrid triangles (dissertation §10.1.8, §10.2.3): a
// triangle fragment adds weight 1 (a splat's kernel peak) of its colour,
// normal and view depth to the same float targets as the splats, so the
// normalisation pass shades both alike and blends them where they meet.
#include "../include/hybrid_fragment.glsl"

layout(location = 0) out vec4 out_color_weight;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out uvec2 out_ids;  // class, instance (never blended)

void main() {
    out_color_weight = vec4(in_color, 1.0);
    out_normal_depth = vec4(normalize(in_normal), -in_position.z);
    out_ids = instance_ids();
}
