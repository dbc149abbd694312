// The text's splat primitives (dissertation §10.3, Table 10.3): an
// object-space quadrilateral in the splat's tangent plane whose corners
// (0,0), (1,0), (1,1), (0,1) are also the texture coordinates of the
// reconstruction kernel, stored in a texture (a 2-D Gaussian cut at F_G).
// The GPU's perspective-correct interpolation maps splat and kernel; there is
// no screen-space EWA set-up and no low-pass prefilter.
//
// Push constants as the other points passes (splat.glsl), except handles.w:
// the kernel texture (sampled) instead of the Gaussian table.
#ifndef ALPENGLOW_OBJECT_SPLAT_GLSL
#define ALPENGLOW_OBJECT_SPLAT_GLSL

#include "splat.glsl"

// SplatPush.primitive of the two object-space primitives (passes.rs).
#define SPLAT_PRIMITIVE_OBJECT_QUAD 3u       // quadruplicated vertices, indexed (4 vertices, 6 indices per splat)
#define SPLAT_PRIMITIVE_OBJECT_INSTANCED 4u  // one 4-vertex quad instanced per splat

#endif
