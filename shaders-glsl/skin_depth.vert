#version 460
// The skin pass's depth pre-pass (skin/shade.rs): the position only. Its
// gl_Position is precise (no fused multiply-adds), as skin.vert's is: the
// same operations on the same inputs, so the depths are equal and the final
// pass's depth test passes exactly where the pre-pass drew.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(location = 0) in vec3 position;   // mm
precise gl_Position;

void main() {
    gl_Position = frame.view_proj * vec4(position, 1.0);
}
