#version 460
// Diffuse shading of the mesh: albedo/π × (SH environment irradiance + explicit
// lights), with the tangent-space normal map. Replaced by texture-space diffusion
// in the skin passes; kept as the `diffuse-direct` view.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh.glsl"
const float PI_F = 3.14159265358979;
layout(binding = 1) uniform sampler2D albedo_tex;   // sRGB format: sampled linear
layout(binding = 2) uniform sampler2D normal_tex;   // tangent space, [0,1] encoded
// SH lighting from sh_reduce.comp: L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22
// (rgb), rotated and scaled by the environment intensity.
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec3 v_t012;
layout(location = 5) in vec3 v_t345;
layout(location = 6) in vec3 v_t678;
#define SHADOW_ATLAS 5
#define SOFT_VISIBILITY 6
#include "lights.glsl"
#include "lighting.glsl"
layout(location = 0) out vec4 color;

#include "normal_map.glsl"

vec3 shading_normal() {
    vec3 s = map_normal(normal_tex, v_uv, v_normal, v_tangent);
    vec3 v = frame.camera_pos.xyz - v_position;
    return seen_from_behind(v_normal, v, shading_dpdx, shading_dpdy) ? -s : s;
}

void main() {
    shading_dpdx = dFdx(v_position);
    shading_dpdy = dFdy(v_position);
    vec3 n = shading_normal();
    vec3 e = irradiance_at(sh_transferred(lighting.sh, v_t012, v_t345, v_t678), v_position, v_normal, n, v_uv, vec2(0.0), 1.0);
    vec3 albedo = texture(albedo_tex, v_uv).rgb;
    color = vec4(albedo / PI_F * e, 1.0);
}
