#version 460
// points.visibility with the object-space primitives (dissertation §10.3,
// §10.2.3): the depth is the rasterised quad's, whose corners the vertex
// stage pushed back by ε; fragments outside the kernel's disk (texel 0) or
// beyond a clip line are discarded. The ids are the winning surfel's.
#include "../include/object_splat_fragment.glsl"

layout(location = 0) out uvec2 out_ids;

void main() {
    if (!(object_splat_weight() > 0.0)) {
        discard;
    }
    out_ids = instance_ids();
}
