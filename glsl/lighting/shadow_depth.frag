#version 460
// Depth-only fragment stage of the shadow casters (§9.5): the rasteriser
// writes the depth; no colour attachment.

void main() {
}
