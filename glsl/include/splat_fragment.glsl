// Per-fragment part of the points passes (dissertation §10.2.2–10.2.4):
// the view ray through the pixel meets the splat's plane (ray–plane depth),
// the tangent coordinates of that point are tested against the clip lines,
// and the screen-space resampling kernel gives the weight.
#ifndef ALPENGLOW_SPLAT_FRAGMENT_GLSL
#define ALPENGLOW_SPLAT_FRAGMENT_GLSL

#include "splat.glsl"

layout(location = 0) flat in vec4 in_conic;
layout(location = 1) flat in vec4 in_centre;
layout(location = 2) flat in vec4 in_position;
layout(location = 3) flat in vec4 in_normal;
layout(location = 4) flat in vec4 in_tu;
layout(location = 5) flat in vec4 in_tv;
layout(location = 6) flat in vec4 in_clip;
layout(location = 7) flat in vec4 in_color;

struct SplatSample {
    vec3 position;  // camera-space point of the splat plane seen through the pixel
    float weight;   // EWA resampling weight
    float r2;       // r² of the resampling kernel (≤ F_G²)
    vec2 uv;        // tangent coordinates (object units)
};

// False when the pixel is outside the splat (kernel cut-off, clip lines, or
// the plane is behind the eye).
bool splat_sample(out SplatSample s) {
    vec2 d = gl_FragCoord.xy - in_centre.xy;
    float r2 = in_conic.x * d.x * d.x + 2.0 * in_conic.y * d.x * d.y + in_conic.z * d.y * d.y;
    float cutoff = g_point_frame[pc.handles.y].depth.w;
    if (r2 > cutoff * cutoff) {
        return false;
    }
    vec3 ray = pixel_ray(gl_FragCoord.xy);
    float denom = dot(in_normal.xyz, ray);
    float t = dot(in_normal.xyz, in_position.xyz) / denom;
    if (!(t > 0.0)) {
        return false;
    }
    vec3 x = ray * t;
    vec3 rel = x - in_position.xyz;
    vec2 uv = vec2(dot(rel, in_tu.xyz), dot(rel, in_tv.xyz));
    if (dot(uv, vec2(cos(in_clip.x), sin(in_clip.x))) > in_clip.y ||
        dot(uv, vec2(cos(in_clip.z), sin(in_clip.z))) > in_clip.w) {
        return false;
    }
    s.position = x;
    s.r2 = r2;
    s.weight = in_conic.w * gaussian(r2, cutoff * cutoff);
    s.uv = uv;
    return true;
}

#endif
