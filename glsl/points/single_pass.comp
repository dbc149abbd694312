#version 460
// points.single_pass with 64-bit atomics (shaderInt64 + shaderBufferInt64Atomics):
// see glsl/include/single_pass.glsl (dissertation §10.4).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define SINGLE_PASS_INT64
#include "../include/single_pass.glsl"
