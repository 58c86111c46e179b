#version 460
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;    // w: bitangent sign
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_tangent;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    v_tangent = tangent;
    gl_Position = frame.view_proj * vec4(position, 1.0);
}
