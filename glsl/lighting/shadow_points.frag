#version 460
// points.shadow, fragment stage: the splat's disc (depth only).

layout(location = 0) in vec2 in_uv;

void main() {
    if (dot(in_uv, in_uv) > 1.0) {
        discard;
    }
}
