#version 460
// mesh_lit.vert plus the vertex's lobe visibility (light/occlusion/lobe.rs)
// and the light the skin reflects onto it and the sky's through thin skin
// (common/indirect.glsl: the final pass's unblurred levels, as the irradiance
// pass has them), for the skin pass and its depth pre-pass (skin/shade.rs):
// one vertex shader for both, so their depths are equal.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 6
#include "transfer.glsl"
layout(std140, binding = 5) uniform Lighting { vec4 sh[9]; } lighting;
#include "indirect.glsl"
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_tangent;
layout(location = 4) out vec3 v_t012;
layout(location = 5) out vec3 v_t345;
layout(location = 6) out vec3 v_t678;
layout(location = 7) out vec3 v_s012;
layout(location = 8) out vec3 v_s345;
layout(location = 9) out vec3 v_s678;
layout(location = 10) out vec3 v_indirect;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    v_tangent = tangent;
    load_transfer(v_t012, v_t345, v_t678);
    load_lobe_visibility(v_s012, v_s345, v_s678);
    v_indirect = indirect_irradiance(position);
    gl_Position = frame.view_proj * vec4(position, 1.0);
}
