#version 460
// points.visibility, hybrid triangles (dissertation §10.1.8, §10.2.3): depth
// pushed back along the view ray by the visibility offset of the object's
// surfels, so that splats of the same surface next to the triangle are
// blended with it in the accumulation pass.
#include "../include/hybrid_fragment.glsl"

layout(location = 0) out uvec2 out_ids;  // class, instance of the winning triangle

void main() {
    vec3 pushed = in_position * (1.0 + in_offset / length(in_position));
    gl_FragDepth = depth_of(pushed.z);
    out_ids = instance_ids();
}
