#version 460
// One triangle covering the screen (sky, points.normalize and any full-screen pass).
layout(location = 0) out vec2 out_ndc;

void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    out_ndc = p * 2.0 - 1.0;
    gl_Position = vec4(out_ndc, 0.0, 1.0);
}
