// Kelemen/Szirmay-Kalos specular (the paper's eq. 1; d'Eon & Luebke, GPU Gems 3
// §14.3, KS_Skin_Specular) with per-region parameters. Expects these bindings
// (numbers set by the including shader through the SPEC_* macros):
//   SPEC_BECKMANN  sampler2D  d'Eon's PH(N·H, m) = π·D, skin/tables.rs::beckmann_table
//   SPEC_ALBEDO    sampler2D  (A(cos θ, m), Ā(m)), skin/tables.rs::albedo_table
//   SPEC_REGIONS   sampler2D  (ρs, m) blended from the face regions' parameters
//                             (skin/specular.rs::region_params_map), nearest
//   SPEC_INTENSITY sampler2D  the specular map s; ρs·(1 + SPEC_MAP_GAIN·min(s/(2s̄), 1))
//                             with 1/(2s̄) in frame.params.y (skin/specular.rs::map_rho_s)
//   SPEC_ROUGHNESS sampler2D  m (grey), used when ROUGHNESS_MAP (frame.glsl)
// The lobe is skin::SkinSettings::lobe: the paper's KS lobe with Schlick's F0 in
// frame.params.x, or with DIELECTRIC_LOBE (frame.glsl) a medium's boundary, a
// rough dielectric of index frame.params.x; the albedo table integrates the lobe.
#include "fresnel.glsl"
layout(binding = SPEC_BECKMANN) uniform sampler2D beckmann_lut;
layout(binding = SPEC_ALBEDO) uniform sampler2D albedo_lut;
layout(binding = SPEC_REGIONS) uniform sampler2D region_params;
layout(binding = SPEC_INTENSITY) uniform sampler2D intensity_tex;
layout(binding = SPEC_ROUGHNESS) uniform sampler2D roughness_tex;

// Endpoint-inclusive tables (skin/specular.rs::table_point): x = i/(n−1) at texel i.
vec2 table_uv(sampler2D table, vec2 x) {
    vec2 n = vec2(textureSize(table, 0));
    return (clamp(x, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
}

// d'Eon's demo maps its specular map to ρs = 0.18 + 0.16·s (skin/specular.rs).
const float SPEC_MAP_GAIN = 0.16 / 0.18;

// (ρs, m) at uv: the face region's (soft at borders), ρs raised by the specular
// map as d'Eon's rule does, m from the roughness map where the scene gives one.
vec2 specular_params(vec2 uv) {
    vec2 params = textureLod(region_params, uv, 0.0).xy;
    params.x *= 1.0 + SPEC_MAP_GAIN * clamp(texture(intensity_tex, uv).r * frame.params.y, 0.0, 1.0);
    if (ROUGHNESS_MAP) params.y = texture(roughness_tex, uv).r;
    params.y = clamp(params.y, 0.02, 1.0);
    return params;
}

// Smith's Λ for Beckmann by Walter et al. 2007's rational fit (eq. 27),
// a = cot θ / m (skin/specular.rs::smith_lambda_rational).
float smith_lambda(float cos_theta, float m) {
    float c = clamp(cos_theta, 1e-4, 1.0);
    float a = c / (m * sqrt(max(1.0 - c * c, 1e-8)));
    return a >= 1.6 ? 0.0 : (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

// KS: N·L · ρs · PH·F / dot(h, h), h = L + V unnormalised (KS 2001: dot(h,h)
// stands for the microfacet denominator). A medium's boundary: ρs·PH·F·G₂/(4 N·V),
// the microfacet BRDF times N·L with ρs = 1/π (skin/specular.rs::Lobe::eval).
// PH from the table.
float ks_specular(vec3 n, vec3 l, vec3 v, vec2 params) {
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) return 0.0;
    vec3 h = l + v;
    vec3 hn = normalize(h);
    float d = texture(beckmann_lut, table_uv(beckmann_lut, vec2(dot(n, hn), params.y))).r;
    if (DIELECTRIC_LOBE) {
        float n_dot_v = max(dot(n, v), 1e-4);
        float f = fresnel_dielectric(max(dot(hn, v), 0.0), frame.params.x);
        float g = 1.0 / (1.0 + smith_lambda(n_dot_l, params.y) + smith_lambda(n_dot_v, params.y));
        return params.x * max(d * f * g / (4.0 * n_dot_v), 0.0);
    }
    float f = fresnel_schlick(dot(hn, v), frame.params.x);
    return n_dot_l * params.x * max(d * f / dot(h, h), 0.0);
}

// (A(cos θ, m), Ā(m)) in one fetch: the specular's directional albedo and its
// cosine-weighted mean over incidence (a row's constant second channel).
vec2 specular_albedos(float cos_theta, float m) {
    return texture(albedo_lut, table_uv(albedo_lut, vec2(cos_theta, m))).rg;
}

// Directional albedo of the KS lobe with ρs = 1, A(cos θ, m) (skin/specular.rs).
float specular_albedo(float cos_theta, float m) {
    return specular_albedos(cos_theta, m).x;
}

// Energy conservation: the share of light at angle θ the specular does not take,
// 1 − ρs·A(cos θ, m) (GPU Gems 3 §14.3).
float diffuse_transmission(float cos_theta, vec2 params) {
    return max(1.0 - params.x * specular_albedo(cos_theta, params.y), 0.0);
}

// The same for light arriving uniformly over the hemisphere, 1 − ρs·Ā(m) with
// Ā = 2∫A(μ)μ dμ (skin/specular.rs::hemispherical_albedo): SH irradiance does
// not keep incidence angles, so the environment is conserved as if uniform.
float diffuse_transmission_uniform(vec2 params) {
    return max(1.0 - params.x * specular_albedos(1.0, params.y).y, 0.0);
}
