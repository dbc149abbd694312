// The sRGB transfer function, shared by the texture atlas and the splats.
#ifndef ALPENGLOW_SRGB_GLSL
#define ALPENGLOW_SRGB_GLSL

// sRGB-encoded `c` in [0, 1] to linear.
vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

#endif
