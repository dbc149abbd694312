#version 460
// post.motion_blur (§3.3: motion blur for the perception of speed;
// src/post/motion_blur.rs): a simplified form of McGuire et al. 2012, "A
// reconstruction filter for plausible motion blur". Per pixel X, N fixed
// stratified samples Y along X's own blur vector v = motion·shutter/dt
// (clamped to a maximum length), centred on X, each the bilinear footprint
// of four texels. A texel counts fully when it lies behind X (X's blur
// reveals it) and otherwise only as far as its own blur reaches X, so a
// sharp foreground is not smeared over a moving background. No tiles or neighbourhood maximum, no cone weights: the CPU
// twin `motion_blur_cpu` lists what was simplified.
#include "../include/resample.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // sampled: radiance, view depth, motion; storage: output (rgba32f)
    uvec4 size;     // width, height, samples
    vec4 params;    // x: shutter / frame interval, y: maximum blur length (px), z: soft depth extent (relative)
} pc;

// The blur vector of texel `q` (pixels, clamped to the maximum length).
vec2 blur_of(ivec2 q) {
    vec2 v = texelFetch(g_textures[pc.handles.z], q, 0).xy * pc.params.x;
    float len = length(v);
    return len > pc.params.y ? v * (pc.params.y / len) : v;
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.x || id.y >= pc.size.y) {
        return;
    }
    ivec2 p = ivec2(id);
    ivec2 n = ivec2(pc.size.xy);
    vec4 centre = texelFetch(g_textures[pc.handles.x], p, 0);
    vec2 v = blur_of(p);
    float len = length(v);
    if (len == 0.0) {
        imageStore(g_images_rgba32f[pc.handles.w], p, centre);
        return;
    }
    float zx = texelFetch(g_textures[pc.handles.y], p, 0).x;
    vec2 x = vec2(p) + 0.5;
    uint samples = pc.size.z;
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (uint i = 0u; i < samples; i++) {
        float t = (float(i) + 0.5) / float(samples) - 0.5;
        vec2 y = clamp(x + t * v, vec2(0.5), vec2(n) - 0.5);
        float d = abs(t) * len;
        // The bilinear footprint of Y, each texel weighted by its own depth
        // and blur, so no colour crosses a depth edge by interpolation.
        vec2 q = y - 0.5;
        vec2 f = floor(q);
        vec2 s = q - f;
        ivec2 base = ivec2(f);
        for (int dy = 0; dy < 2; dy++) {
            for (int dx = 0; dx < 2; dx++) {
                float b = (dx == 0 ? 1.0 - s.x : s.x) * (dy == 0 ? 1.0 - s.y : s.y);
                if (b > 0.0) {
                    ivec2 tap = clamp(base + ivec2(dx, dy), ivec2(0), n - 1);
                    float zy = texelFetch(g_textures[pc.handles.y], tap, 0).x;
                    float behind = zy > zx ? clamp((zy - zx) / (pc.params.z * zx), 0.0, 1.0) : 0.0;
                    float reach = clamp(0.5 * length(blur_of(tap)) + 1.0 - d, 0.0, 1.0);
                    float w = b * (behind + (1.0 - behind) * reach);
                    if (w > 0.0) {
                        sum += w * texelFetch(g_textures[pc.handles.x], tap, 0);
                        total += w;
                    }
                }
            }
        }
    }
    imageStore(g_images_rgba32f[pc.handles.w], p, total > 0.0 ? sum / total : centre);
}
