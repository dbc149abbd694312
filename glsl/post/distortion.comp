#version 460
// post.distortion (§3.3: the cameras of a driving simulator; src/post/distortion):
// what a real camera with Brown–Conrady lens distortion sees, resampled from
// an undistorted pinhole render. The source position of every output pixel
// (OpenCV pixel coordinates, texel k's centre at k) was found on the CPU by
// inverting the distortion and is read from a buffer. Filtered images:
// bilinear; Exact: the nearest texel; Motion: the nearest texel, its
// displacement carried into the output's pixels by the derivative of the
// mapping, F·J_D·F'⁻¹ (J_D the Jacobian of the distortion at the ray).
#include "../include/resample.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 2, std430) readonly buffer SourceMap { vec2 position[]; } g_maps[];

layout(push_constant) uniform Push {
    uvec4 handles;  // x: source (sampled), y: target (storage), z: map buffer, w: format code
    uvec4 size;     // source width, height; target width, height
    uvec4 mode;     // x: kind
    vec4 radial;    // k1, k2, k3, p1
    vec4 tangential;  // p2
    vec4 focal;     // fx', fy' of the source
    vec4 centre;    // cx', cy' of the source
    vec4 ratios;    // fx/fx', fx/fy', fy/fx', fy/fy' (F·J·F'⁻¹ = J scaled by these)
} pc;

// The displacement `m` (source pixels) at source position `q`, in output pixels.
vec2 carry_motion(vec2 m, vec2 q) {
    float k1 = pc.radial.x, k2 = pc.radial.y, k3 = pc.radial.z;
    float p1 = pc.radial.w, p2 = pc.tangential.x;
    vec2 xy = (q - pc.centre.xy) / pc.focal.xy;
    float x = xy.x, y = xy.y;
    float r2 = x * x + y * y;
    float radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    float slope = k1 + r2 * (2.0 * k2 + r2 * 3.0 * k3);
    float jxx = radial + 2.0 * x * x * slope + 2.0 * p1 * y + 6.0 * p2 * x;
    float jxy = 2.0 * x * y * slope + 2.0 * p1 * x + 2.0 * p2 * y;
    float jyy = radial + 2.0 * y * y * slope + 6.0 * p1 * y + 2.0 * p2 * x;
    vec4 r = pc.ratios;
    return vec2(jxx * r.x * m.x + jxy * r.y * m.y, jxy * r.z * m.x + jyy * r.w * m.y);
}

void main() {
    uvec2 id = gl_GlobalInvocationID.xy;
    if (id.x >= pc.size.z || id.y >= pc.size.w) {
        return;
    }
    ivec2 p = ivec2(id);
    ivec2 n = ivec2(pc.size.xy);
    vec2 q = g_maps[pc.handles.z].position[id.y * pc.size.z + id.x];
    uint format = pc.handles.w;
    uint kind = pc.mode.x;
    if (kind == KIND_FILTERED) {
        store_float(format, pc.handles.y, p, bilinear(pc.handles.x, q, n));
        return;
    }
    ivec2 nearest = clamp(ivec2(floor(q + 0.5)), ivec2(0), n - 1);
    if (kind == KIND_MOTION) {
        vec4 m = texelFetch(g_textures[pc.handles.x], nearest, 0);
        store_float(format, pc.handles.y, p, vec4(carry_motion(m.xy, q), m.zw));
    } else {
        copy_texel(format, pc.handles.x, pc.handles.y, nearest, p);
    }
}
