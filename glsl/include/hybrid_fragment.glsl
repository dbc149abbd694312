// Fragment inputs of the hybrid triangles (glsl/points/hybrid.vert).
#ifndef ALPENGLOW_HYBRID_FRAGMENT_GLSL
#define ALPENGLOW_HYBRID_FRAGMENT_GLSL

#include "hybrid.glsl"

layout(location = 0) in vec3 in_position;      // camera space
layout(location = 1) in vec3 in_normal;        // camera space
layout(location = 2) in vec3 in_color;         // linear albedo
layout(location = 3) flat in float in_offset;  // visibility offset (camera units)

#endif
