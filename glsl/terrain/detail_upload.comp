#version 460
// terrain.detail (issue 31 item 1, §7.4.4): copies the tiles that arrived
// this frame from the upload region into their slots of the detail window
// (src/terrain/detail/pass.rs writes the records: texel corner and size,
// then tile_side² heights, rows tile_side apart). Group z: the record.
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(set = 0, binding = 2, std430) readonly buffer Tiles { uint w[]; } g_tiles[];

layout(push_constant) uniform Push {
    uvec4 handles;  // upload region (storage), window image (storage), tiles, tile side
} pc;

void main() {
    uint t = pc.handles.w;
    uint base = gl_WorkGroupID.z * (4u + t * t);
    uvec4 head = uvec4(g_tiles[pc.handles.x].w[base], g_tiles[pc.handles.x].w[base + 1u],
                       g_tiles[pc.handles.x].w[base + 2u], g_tiles[pc.handles.x].w[base + 3u]);
    uvec2 at = gl_GlobalInvocationID.xy;
    if (at.x >= head.z || at.y >= head.w) {
        return;
    }
    float h = uintBitsToFloat(g_tiles[pc.handles.x].w[base + 4u + at.y * t + at.x]);
    imageStore(g_images_r32f[pc.handles.y], ivec2(head.xy + at), vec4(h));
}
