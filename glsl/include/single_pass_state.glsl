// The per-pixel state of single-pass splatting's interlock backend
// (dissertation §10.4): the sums of glsl/include/single_pass_merge.glsl, as
// its clear and resolve passes read them. Layout:
// src/points/render/single_pass/interlock.rs (PIXEL_SUM_BYTES).
#ifndef ALPENGLOW_SINGLE_PASS_STATE_GLSL
#define ALPENGLOW_SINGLE_PASS_STATE_GLSL

struct PixelSums {
    vec4 color_weight;  // A_d·C_d, A_d
    vec4 normal_depth;  // A_d·n, A_d·view depth
    uvec4 ids;          // class, instance of the splat that set z_d; 0, 0
};

#endif
