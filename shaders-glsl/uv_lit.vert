#version 460
// uv.vert plus the vertex's SH transfer, for the irradiance pass, and the light
// the skin reflects onto the vertex and the sky's through thin skin
// (common/indirect.glsl).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 14
#include "transfer.glsl"
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
#include "indirect.glsl"
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 4) out vec3 v_t012;
layout(location = 5) out vec3 v_t345;
layout(location = 6) out vec3 v_t678;
layout(location = 7) out vec3 v_indirect;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    load_transfer(v_t012, v_t345, v_t678);
    v_indirect = indirect_irradiance(position);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
