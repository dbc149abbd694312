// The tangent frame of a splat's normal, shared by the points passes
// (glsl/include/splat.glsl) and the point shadow casters
// (glsl/include/shadow_points.glsl).
#ifndef ALPENGLOW_TANGENT_FRAME_GLSL
#define ALPENGLOW_TANGENT_FRAME_GLSL

// Orthonormal tangent frame of a unit normal (Duff et al. 2017);
// src/points/clip.rs::tangent_frame is the same.
void tangent_frame(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float bb = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * bb, -s * n.x);
    b = vec3(bb, s + n.y * n.y * a, -n.y);
}

#endif
