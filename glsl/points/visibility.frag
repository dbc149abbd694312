#version 460
// points.visibility (dissertation §10.2.3, Table 10.1 pass 1): depth only.
// Each fragment's depth is the ray–splat-plane intersection pushed back along
// the view ray by ε (a fraction of the splat radius), so that the
// accumulation pass blends every splat within ε of the nearest surface.
// The ids AOV (class, instance) is the winning surfel's: a single surfel,
// never a blend.
#include "../include/splat_fragment.glsl"

layout(location = 0) out uvec2 out_ids;

void main() {
    SplatSample s;
    if (!splat_sample(s)) {
        discard;
    }
    float offset = g_point_frame[pc.handles.y].depth.z * in_centre.z;
    vec3 pushed = s.position * (1.0 + offset / length(s.position));
    gl_FragDepth = depth_of(pushed.z);
    out_ids = instance_ids();
}
