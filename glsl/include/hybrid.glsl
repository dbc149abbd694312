// Triangles of hybrid point–polygon objects (dissertation §10.1.8): drawn
// where they are larger than the error threshold in the image, in the same
// passes as the splats. Layout matches GpuTriangle in
// src/points/render/gpu_layout.rs.
#ifndef ALPENGLOW_HYBRID_GLSL
#define ALPENGLOW_HYBRID_GLSL

#include "splat.glsl"

struct HybridTriangle {
    vec4 p[3];  // object-space corners; p[0].w = r_max = s/ε, p[1].w = surfel radius (object units)
    vec4 n[3];  // object-space unit vertex normals; w = sRGB colour (uint bits: r | g << 8 | b << 16)
};

layout(set = 0, binding = 2, std430) readonly buffer HybridTriangles { HybridTriangle t[]; } g_hybrid_triangles[];

#endif
