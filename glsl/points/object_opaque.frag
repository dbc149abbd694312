#version 460
// points.opaque with the object-space primitives (dissertation §10.3): the
// kernel's disk (texel > 0) as an opaque disc with the quad's own depth,
// shaded directly as opaque.frag; world normal and ids AOVs.
#include "../include/object_splat_fragment.glsl"
#include "../include/splat_shading.glsl"

layout(location = 0) out vec4 out_radiance;
layout(location = 1) out float out_view_depth;
layout(location = 2) out float out_weight;
layout(location = 3) out vec2 out_visibility;
layout(location = 4) out vec4 out_normal;
layout(location = 5) out uvec2 out_ids;

void main() {
    if (!(object_splat_weight() > 0.0)) {
        discard;
    }
    out_radiance = vec4(shade_splat(in_color.rgb, in_normal.xyz, in_position, out_visibility), 1.0);
    out_view_depth = -in_position.z;
    out_weight = 1.0;
    out_normal = world_normal(in_normal.xyz, in_position);
    out_ids = instance_ids();
}
