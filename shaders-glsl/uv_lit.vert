#version 460
// uv.vert plus, for the irradiance pass, the environment's irradiance at the
// vertex through its SH transfer and the light the skin reflects onto it and
// the sky's through thin skin (common/indirect.glsl): linear in the transfer,
// so interpolated as three numbers instead of twelve (lighting.glsl).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 14
#include "transfer.glsl"
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
#include "sh.glsl"
#include "indirect.glsl"
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 4) out vec3 v_occluded;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    v_occluded = occluded_irradiance(position);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
