#version 460
// terrain.grid: evaluates the height field on a regular grid and writes
// position and normal of every vertex into a storage buffer that the next
// pass draws as its vertex buffer (render-to-vertex-buffer, §7.4.4).
#include "../include/heap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

struct Vertex {
    vec4 position; // world xyz, 1
    vec4 normal;   // world xyz, 0
};

layout(set = 0, binding = 2, std430) writeonly buffer Vertices { Vertex v[]; } g_vertices[];

layout(push_constant) uniform Push {
    vec4 spacing;       // dx, dy (metres per height sample), height scale, height offset
    uvec4 grid;         // grid columns, grid rows, height columns, height rows
    uvec4 handles;      // heights (sampled), vertices (storage buffer)
} pc;

float height_at(vec2 sample_coord) {
    // sample_coord in height-field samples; texel centres sit at integer + 0.5.
    vec2 size = vec2(pc.grid.zw);
    vec2 uv = (clamp(sample_coord, vec2(0.0), size - 1.0) + 0.5) / size;
    float h = textureLod(sampler2D(g_textures[pc.handles.x], g_samplers[SAMPLER_LINEAR_CLAMP]), uv, 0.0).r;
    return h * pc.spacing.z + pc.spacing.w;
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.grid.x || id.y >= pc.grid.y) {
        return;
    }
    vec2 samples_per_cell = vec2(pc.grid.zw - 1u) / vec2(pc.grid.xy - 1u);
    vec2 coord = vec2(id) * samples_per_cell;
    float h = height_at(coord);
    vec2 step_size = max(samples_per_cell, vec2(1.0));
    float hl = height_at(coord - vec2(step_size.x, 0.0));
    float hr = height_at(coord + vec2(step_size.x, 0.0));
    float hd = height_at(coord - vec2(0.0, step_size.y));
    float hu = height_at(coord + vec2(0.0, step_size.y));
    vec2 world_step = 2.0 * step_size * pc.spacing.xy;
    vec3 normal = normalize(vec3(-(hr - hl) / world_step.x, -(hu - hd) / world_step.y, 1.0));
    uint index = id.y * pc.grid.x + id.x;
    g_vertices[pc.handles.y].v[index].position = vec4(coord * pc.spacing.xy, h, 1.0);
    g_vertices[pc.handles.y].v[index].normal = vec4(normal, 0.0);
}
