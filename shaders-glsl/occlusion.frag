#version 460
// `--view occlusion`: the vertex's visibility (common/visibility.glsl).
#extension GL_GOOGLE_include_directive : require
#include "visibility.glsl"
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec3 v_t012;
layout(location = 5) in vec3 v_t345;
layout(location = 6) in vec3 v_t678;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(vec3(open_sky(v_t012.x)), 1.0);
}
