#version 460
// points.single_pass with 32-bit atomics only (the fallback without
// shaderBufferInt64Atomics): see glsl/include/single_pass.glsl (§10.4).
#include "../include/single_pass.glsl"
