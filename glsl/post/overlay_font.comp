#version 460
// overlay.font: a rectangle of the overlay's font atlas (egui's texture
// delta, RGBA8 premultiplied, one word a texel, rows packed) from the
// frame's upload region into the atlas image.
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 2, std430) readonly buffer Texels { uint texels[]; } g_texels[];

layout(push_constant) uniform Push {
    uvec4 handles;  // texels (upload), atlas (storage rgba8)
    uvec4 rect;     // x, y, width, height in the atlas
} pc;

void main() {
    uvec2 at = gl_GlobalInvocationID.xy;
    if (at.x >= pc.rect.z || at.y >= pc.rect.w) {
        return;
    }
    uint texel = g_texels[pc.handles.x].texels[at.y * pc.rect.z + at.x];
    imageStore(g_images_rgba8[pc.handles.y], ivec2(pc.rect.xy + at), unpackUnorm4x8(texel));
}
