// Per-fragment part of the points passes (dissertation §10.2.2–10.2.4): the
// flat varyings of glsl/points/splat.vert and the kernel of
// glsl/include/splat_setup.glsl at the fragment's pixel centre.
#ifndef ALPENGLOW_SPLAT_FRAGMENT_GLSL
#define ALPENGLOW_SPLAT_FRAGMENT_GLSL

#include "splat_setup.glsl"

layout(location = 0) flat in vec4 in_conic;
layout(location = 1) flat in vec4 in_centre;
layout(location = 2) flat in vec4 in_position;
layout(location = 3) flat in vec4 in_normal;
layout(location = 4) flat in vec4 in_tu;
layout(location = 5) flat in vec4 in_tv;
layout(location = 6) flat in vec4 in_clip;
layout(location = 7) flat in vec4 in_color;

// The splat of the varyings.
SplatSetup splat_varyings() {
    SplatSetup v;
    v.conic = in_conic;
    v.centre = in_centre;
    v.position = in_position;
    v.normal = in_normal;
    v.tu = in_tu;
    v.tv = in_tv;
    v.clip = in_clip;
    v.color = in_color;
    v.half_extent = vec2(0.0);
    return v;
}

// False when the fragment is outside the splat (kernel cut-off, clip lines,
// or the plane is behind the eye).
bool splat_sample(out SplatSample s) {
    return splat_sample_at(gl_FragCoord.xy, splat_varyings(), s);
}

#endif
