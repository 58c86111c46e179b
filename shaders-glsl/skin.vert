#version 460
// mesh.vert plus, for the skin pass (skin/shade.rs): the environment's
// irradiance at the vertex through its SH transfer plus the light the skin
// reflects onto it and the sky's through thin skin (common/indirect.glsl;
// the final pass's unblurred levels, as uv_lit.vert and irradiance_vertices.comp
// have it for the irradiance pass), and the vertex's lobe visibility (light/occlusion/lobe.rs).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 6
#include "transfer.glsl"
layout(std140, binding = 5) uniform Lighting { vec4 sh[9]; } lighting;
#include "sh.glsl"
#include "indirect.glsl"
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_tangent;
layout(location = 4) out vec3 v_occluded;
layout(location = 5) out vec3 v_s012;
layout(location = 6) out vec3 v_s345;
layout(location = 7) out vec3 v_s678;
// As skin_depth.vert's, so the pre-pass's depths are the final pass's.
precise gl_Position;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    v_tangent = tangent;
    v_occluded = occluded_irradiance(position);
    load_lobe_visibility(v_s012, v_s345, v_s678);
    gl_Position = frame.view_proj * vec4(position, 1.0);
}
