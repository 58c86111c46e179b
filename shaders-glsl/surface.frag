#version 460
// The irradiance pass's surface terms, which no light changes: drawn once per
// render over the same UV raster as irradiance.frag, which reads them back
// texel for texel (skin/irradiance.rs; issue 24). (n, ρs): the normal-mapped
// shading normal and the specular's strength; (albedo^mix, m): the pre-scatter
// albedo (GPU Gems 3 §14.5) and the lobe's roughness.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(binding = 1) uniform sampler2D albedo_tex;
layout(binding = 2) uniform sampler2D normal_tex;
layout(push_constant) uniform Push { float mix_pre; } pc;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
#define SPEC_BECKMANN 3
#define SPEC_ALBEDO 4
#define SPEC_REGIONS 5
#define SPEC_INTENSITY 6
#define SPEC_ROUGHNESS 7
#include "ks_specular.glsl"
#include "normal_map.glsl"
layout(location = 0) out vec4 normal_rho;
layout(location = 1) out vec4 albedo_m;

void main() {
    vec2 params = specular_params(v_uv);
    normal_rho = vec4(map_normal(normal_tex, v_uv, v_normal, v_tangent), params.x);
    albedo_m = vec4(pow(texture(albedo_tex, v_uv).rgb, vec3(pc.mix_pre)), params.y);
}
