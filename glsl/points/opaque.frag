#version 460
// points.opaque: the fast baseline splat mode — opaque discs (the kernel's
// cut-off ellipse, i.e. the projected disk, §10.2.2) with ray–plane depth,
// depth-tested and shaded directly, no blending; world normal and ids AOVs.
#include "../include/splat_fragment.glsl"
#include "../include/splat_shading.glsl"

layout(location = 0) out vec4 out_radiance;
layout(location = 1) out float out_view_depth;
layout(location = 2) out float out_weight;
layout(location = 3) out vec2 out_visibility;
layout(location = 4) out vec4 out_normal;
layout(location = 5) out uvec2 out_ids;

void main() {
    SplatSample s;
    if (!splat_sample(s)) {
        discard;
    }
    gl_FragDepth = depth_of(s.position.z);
    out_radiance = vec4(shade_splat(in_color.rgb, in_normal.xyz, s.position, out_visibility), 1.0);
    out_view_depth = -s.position.z;
    out_weight = 1.0;
    out_normal = world_normal(in_normal.xyz, s.position);
    out_ids = instance_ids();
}
