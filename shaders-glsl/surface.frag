#version 460
// The irradiance pass's surface terms, which no light changes: drawn once per
// render over the same UV raster as irradiance.frag and the texel map
// (texel_map.vert), and read back texel for texel by irradiance.frag or
// irradiance.comp (skin/irradiance.rs). Two RGBA16 UNORM targets
// (1.5·10⁻⁵ steps over [0, 1], finer than half floats there): the normal-mapped
// shading normal, octahedral (common/octahedral.glsl), with the specular's (ρs,
// m); and the pre-scatter albedo^mix (GPU Gems 3 §14.5) with the share of the
// environment's light that enters, 1 − ρs·Ā(m) (ks_specular.glsl).
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
#include "octahedral.glsl"
layout(location = 0) out vec4 normal_params;
layout(location = 1) out vec4 albedo_mix;

void main() {
    vec2 params = specular_params(v_uv);
    vec3 n = map_normal(normal_tex, v_uv, v_normal, v_tangent);
    normal_params = vec4(octahedral_encode(n) * 0.5 + 0.5, params);
    albedo_mix = vec4(pow(texture(albedo_tex, v_uv).rgb, vec3(pc.mix_pre)),
                      diffuse_transmission_uniform(params));
}
