#version 460
// Irradiance in texture space (GPU Gems 3 §14.5): SH environment irradiance
// (Ramamoorthi & Hanrahan 2001) plus the explicit lights (shadowed), less what the
// specular reflects (energy conservation on entry), times the pre-scatter
// albedo^mix. Alpha is coverage (1 on the mesh, 0 in the gutter). A compute
// pass over the texel map (texel_map.frag, drawn once per render): each covered
// texel interpolates its triangle's vertices' position and occluded irradiance
// (irradiance_vertices.comp, per frame) with its stored weights, as a raster
// of the mesh by its UVs would at the texel's centre. The shading normal,
// albedo^mix, (ρs, m) and the environment's share 1 − ρs·Ā(m) were drawn once
// per render by surface.frag over the same raster and are read texel for texel,
// as are the shadowed lights' visibility (light/visibility.rs).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
layout(local_size_x = 8, local_size_y = 8) in;
#include "frame.glsl"
#include "sh.glsl"
layout(binding = 1) uniform sampler2D surface_normal_params;
layout(binding = 2) uniform sampler2D surface_albedo_mix;
// SH lighting from sh_reduce.comp: L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22
// (rgb), rotated and scaled by the environment intensity.
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
layout(binding = 4) uniform usampler2D texel_map;
#define SPEC_BECKMANN 5
#define SPEC_ALBEDO 6
#define SPEC_REGIONS 7
#define SPEC_INTENSITY 8
#define SPEC_ROUGHNESS 9
#include "ks_specular.glsl"
#include "octahedral.glsl"
#define SHADOW_ATLAS 10
#define SOFT_VISIBILITY 11
layout(binding = 14) uniform sampler2D vertex_values;
#define HARD_VISIBILITY 15
vec2 shading_point;
#define SHADING_POINT shading_point
#include "lights.glsl"
#define ENERGY_CONSERVING
#include "lighting.glsl"
layout(binding = 18, rgba16f) uniform writeonly image2D irradiance;
#include "vertices.glsl"

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(irradiance);
    if (any(greaterThanEqual(texel, size))) return;
    uvec4 t = texelFetch(texel_map, texel, 0);
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    imageStore(irradiance, texel, vec4(unpackUnorm2x16(t.w), 0.0, float(t.x != 0u)));
    return;
#endif
    if (t.x == 0u) {
        imageStore(irradiance, texel, vec4(0.0));
        return;
    }
    vec2 w12 = unpackUnorm2x16(t.w);
    vec3 w = vec3(1.0 - w12.x - w12.y, w12);
    vec3 x = vec3(0.0), occluded = vec3(0.0);
    [[unroll]] for (int k = 0; k < 3; ++k) {
        ivec2 at = vertex_values_texel(t[k] - 1u, textureSize(vertex_values, 0).x);
        x += w[k] * texelFetch(vertex_values, at, 0).xyz;
        occluded += w[k] * texelFetch(vertex_values, at + ivec2(1, 0), 0).xyz;
    }
    shading_point = vec2(texel) + 0.5;
    vec2 uv = shading_point / vec2(size);
    vec4 s = texelFetch(surface_normal_params, texel, 0);
    vec3 n = octahedral_decode(s.xy * 2.0 - 1.0);
    vec4 a = texelFetch(surface_albedo_mix, texel, 0);
    // The geometric normal only offsets shadow lookups, and this pass reads
    // every shadowed light's visibility stored: the shading normal stands in.
    vec3 e = irradiance_at(occluded, x, n, n, uv, s.zw, a.a);
    imageStore(irradiance, texel, vec4(e * a.rgb, 1.0));
}
