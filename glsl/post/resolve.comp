#version 460
// post.resolve (§3.3: anti-aliasing for driving simulators; src/post/resolve.rs):
// one image of a view rendered supersampled (W'×H') down to the output
// (W×H). Filtered images: a box filter over the output pixel's footprint
// (weights = the area each source pixel shares with it) or a tent of radius
// one output pixel, normalised. Exact images (ids, depth, normals): the one
// source sample nearest the output pixel's centre, in integer arithmetic so
// every image of the view takes the same sample. Motion: that sample, its
// displacement scaled by W/W', H/H'. The CPU twin is `resolve_*_cpu`.
#include "../include/resample.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
    uvec4 handles;  // x: source (sampled), y: target (storage), z: format code, w: kind
    uvec4 size;     // source width, height; target width, height
    vec4 params;    // xy: source pixels per target pixel (W'/W, H'/H); z: filter (0 box, 1 tent)
    vec4 motion;    // xy: factors of a motion image's x and y (W/W', H/H')
} pc;

// First and last source texel of target pixel `i` along one axis, clamped
// to the source's `n` texels.
ivec2 taps(int i, float s, int n, bool tent) {
    int first, last;
    if (tent) {
        float c = (float(i) + 0.5) * s;
        first = int(ceil(c - s - 0.5));
        last = int(floor(c + s - 0.5));
    } else {
        first = int(floor(float(i) * s));
        last = int(ceil(float(i + 1) * s)) - 1;
    }
    return ivec2(max(first, 0), min(last, n - 1));
}

// The weight of source texel `k` for target pixel `i` along one axis.
float weight(int k, int i, float s, bool tent) {
    if (tent) {
        float c = (float(i) + 0.5) * s;
        return max(1.0 - abs(float(k) + 0.5 - c) / s, 0.0);
    }
    float a = float(i) * s;
    float b = float(i + 1) * s;
    return max(min(float(k + 1), b) - max(float(k), a), 0.0);
}

vec4 filtered(ivec2 p) {
    bool tent = pc.params.z > 0.5;
    ivec2 n = ivec2(pc.size.xy);
    ivec2 xs = taps(p.x, pc.params.x, n.x, tent);
    ivec2 ys = taps(p.y, pc.params.y, n.y, tent);
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int y = ys.x; y <= ys.y; y++) {
        float wy = weight(y, p.y, pc.params.y, tent);
        for (int x = xs.x; x <= xs.y; x++) {
            float w = weight(x, p.x, pc.params.x, tent) * wy;
            if (w > 0.0) {
                sum += w * texelFetch(g_textures[pc.handles.x], ivec2(x, y), 0);
                total += w;
            }
        }
    }
    return sum / total;
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.z || id.y >= pc.size.w) {
        return;
    }
    ivec2 p = ivec2(id);
    uint format = pc.handles.z;
    uint kind = pc.handles.w;
    if (kind == KIND_FILTERED) {
        store_float(format, pc.handles.y, p, filtered(p));
        return;
    }
    // The source texel whose centre is nearest to the target pixel's centre
    // (i + 1/2)·W'/W: floor((2i + 1)·W' / 2W), ties to the larger index.
    ivec2 q = ivec2(((2u * id + 1u) * pc.size.xy) / (2u * pc.size.zw));
    if (kind == KIND_MOTION) {
        vec4 m = texelFetch(g_textures[pc.handles.x], q, 0);
        store_float(format, pc.handles.y, p, vec4(m.xy * pc.motion.xy, m.zw));
    } else {
        copy_texel(format, pc.handles.x, pc.handles.y, q, p);
    }
}
