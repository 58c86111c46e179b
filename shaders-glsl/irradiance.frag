#version 460
// Irradiance in texture space (GPU Gems 3 §14.5): SH environment irradiance
// (Ramamoorthi & Hanrahan 2001) plus the explicit lights (shadowed), less what the
// specular reflects (energy conservation on entry), times the pre-scatter
// albedo^mix. Alpha is coverage (1 on the mesh, 0 in the gutter). The shading
// normal, albedo^mix, (ρs, m) and the environment's share 1 − ρs·Ā(m) were
// drawn once per render by surface.frag over this same raster and are read
// texel for texel.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh.glsl"
layout(binding = 1) uniform sampler2D surface_normal_params;
layout(binding = 2) uniform sampler2D surface_albedo_mix;
// SH lighting from sh_reduce.comp: L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22
// (rgb), rotated and scaled by the environment intensity.
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
// The environment's irradiance through the transfer, plus the light the skin
// reflects onto itself and the sky's through thin skin (uv_lit.vert).
layout(location = 4) in vec3 v_occluded;
#define SPEC_BECKMANN 5
#define SPEC_ALBEDO 6
#define SPEC_REGIONS 7
#define SPEC_INTENSITY 8
#define SPEC_ROUGHNESS 9
#include "ks_specular.glsl"
#include "octahedral.glsl"
#define SHADOW_ATLAS 10
#define SOFT_VISIBILITY 11
// Bindings 15..17 (after the per-vertex colour's 14): the other shadowed
// lights' visibility, drawn over this raster (light/visibility.rs).
#define HARD_VISIBILITY 15
#include "lights.glsl"
#define ENERGY_CONSERVING
#include "lighting.glsl"
layout(location = 0) out vec4 irradiance;

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 s = texelFetch(surface_normal_params, texel, 0);
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    irradiance = vec4(s.zw, 0.0, 1.0);
    return;
#endif
    vec3 n = octahedral_decode(s.xy * 2.0 - 1.0);
    vec4 a = texelFetch(surface_albedo_mix, texel, 0);
    vec3 e = irradiance_at(v_occluded, v_position, v_normal, n, v_uv, s.zw, a.a);
    irradiance = vec4(e * a.rgb, 1.0);
}
