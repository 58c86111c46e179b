#version 460
// Final skin shading (GPU Gems 3 §14.5; the paper's Fig. 2): the diffusion
// profile as Σ w_i · blur_i, each blur normalised by its coverage, times the
// post-scatter albedo^(1-mix); Lambert's 1/π turns irradiance into radiance.
// Plus the KS specular (the paper's eq. 1) of the explicit lights and of the
// environment (split sum: ρs·A(N·V, m) × the KS-prefiltered environment).
// With TRANSMISSION, the light of shadowed lights behind the skin transmitted
// through it adds to the diffuse (docs/records/2026-11-26-transmission.md, "Transmission"), from the
// texture translucent.frag drew once per lighting for the side shaded.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "envmap.glsl"
layout(binding = 1) uniform sampler2D albedo_tex;
layout(binding = 2) uniform sampler2D normal_tex;
#define SHADOW_ATLAS 3
#define SOFT_VISIBILITY 20
// Bindings 20..22: the soft lights' visibility.
#include "lights.glsl"
// The light transmitted through thin skin, front and back (skin/translucent.rs).
layout(binding = 23) uniform sampler2D translucent_front;
layout(binding = 24) uniform sampler2D translucent_back;
// Bindings 4 and 6: the per-vertex transfer and lobe visibility, and the
// interreflected and transmitted transfer, read by skin.vert. 5: the
// environment's SH (sh_reduce.comp), for the unblurred levels.
layout(std140, binding = 5) uniform Lighting { vec4 sh[9]; } lighting;
#define ENV_SPECULAR 7
#include "env_specular.glsl"
layout(binding = 8) uniform sampler2D irradiance;
layout(binding = 9) uniform sampler2D blur1;
layout(binding = 10) uniform sampler2D blur2;
layout(binding = 11) uniform sampler2D blur3;
layout(binding = 12) uniform sampler2D blur4;
layout(binding = 13) uniform sampler2D blur5;
layout(binding = 14) uniform sampler2D blur6;
#define SPEC_BECKMANN 15
#define SPEC_ALBEDO 16
#define SPEC_REGIONS 17
#define SPEC_INTENSITY 18
#define SPEC_ROUGHNESS 19
#include "ks_specular.glsl"
#include "normal_map.glsl"
#include "lobe_visibility.glsl"
// weights: rgb the Gaussians' weights (w: padding); pixel_weight: the sum of
// the per-pixel levels' (PIXEL_LEVELS). mode: 0 final, 1 diffuse
// only, 2 specular only, 3 the transmitted light only. blur_amount: the share
// of the blurred levels, the rest the unblurred irradiance (the paper's menu).
// transmission: the scale on the transmitted light (skin.transmission).
layout(push_constant) uniform Push {
    vec4 weights[6];
    float mix_pre;
    uint mode;
    float blur_amount;
    float transmission;
    vec4 pixel_weight;
} pc;
// The pass is built with the transmitted term (skin::shade::ShadePass::new);
// without it the shader is the one without the term.
layout(constant_id = 6) const bool TRANSMISSION = false;
// With blur_amount < 1 the unblurred irradiance is mixed in; at 1 (the
// default) the pass is built without its lookup (skin::shade::ShadePass::new).
layout(constant_id = 7) const bool UNBLURRED = true;
// The leading levels the chain leaves unblurred (skin::chain: the adaptive
// chain's first, narrower than SKIP_SIGMA_TEXELS) are the irradiance itself:
// PIXEL_LEVELS of them, evaluated at the pixel as the irradiance pass does at a
// texel, and not read from their textures (skin::shade::ShadePass::new).
layout(constant_id = 8) const uint PIXEL_LEVELS = 0;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
// The environment's irradiance through the transfer plus the light the skin
// reflects onto itself and the sky's through thin skin (skin.vert), and the
// lobe visibility's SH.
layout(location = 4) in vec3 v_occluded;
layout(location = 5) in vec3 v_s012;
layout(location = 6) in vec3 v_s345;
layout(location = 7) in vec3 v_s678;
layout(location = 0) out vec4 color;
#include "sh.glsl"
#define ENERGY_CONSERVING
#include "lighting.glsl"

// A UV target at v_uv, normalised by its coverage.
vec3 lookup(sampler2D t) {
    vec4 b = textureLod(t, v_uv, 0.0);
    return b.rgb / max(b.a, 1e-4);
}

// Level k's share, read from its texture t unless it is evaluated per pixel
// (a constant: the lookup is compiled out).
vec3 level(uint k, sampler2D t) {
    return k < PIXEL_LEVELS ? vec3(0.0) : pc.weights[k].rgb * lookup(t);
}

void main() {
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    color = vec4(texture(albedo_tex, v_uv).rgb, 1.0);
    return;
#endif
    shading_dpdx = dFdx(v_position);
    shading_dpdy = dFdy(v_position);
    vec3 blurred = level(0u, blur1) + level(1u, blur2) + level(2u, blur3)
                 + level(3u, blur4) + level(4u, blur5) + level(5u, blur6);
    vec3 n = map_normal(normal_tex, v_uv, v_normal, v_tangent);
    vec2 params = specular_params(v_uv);
    vec3 albedo = texture(albedo_tex, v_uv).rgb;
    vec3 v = normalize(frame.camera_pos.xyz - v_position);
    bool back_side = seen_from_behind(v_normal, v, shading_dpdx, shading_dpdy);
    float n_dot_v = clamp(dot(back_side ? -n : n, v), 0.0, 1.0);
    // (A(N·V, m), Ā(m)): the specular's albedo toward the viewer and over
    // the hemisphere.
    vec2 albedos = specular_albedos(n_dot_v, params.y);
    // The irradiance pass's term at this pixel, the front side's as in its
    // texture; the environment's share that enters, 1 − ρs·Ā(m), from the
    // fetch above.
    if (PIXEL_LEVELS > 0u) {
        float env_share = max(1.0 - params.x * albedos.y, 0.0);
        blurred += pc.pixel_weight.rgb * irradiance_at(v_occluded, v_position, v_normal, n, v_uv, params, env_share)
                 * pow(albedo, vec3(pc.mix_pre));
    }
    vec3 diffuse = UNBLURRED ? mix(lookup(irradiance), blurred, pc.blur_amount) : blurred;
    if (back_side) n = -n;
    // ρs·A(N·V, m): what the oil layer reflects toward the viewer (GPU Gems 3
    // §14.3), taken from the diffuse and given to the environment's specular.
    float reflected = params.x * albedos.x;
    // What the oil layer reflects back inward on exit stays in the skin and
    // leaves later: the exit factor 1 − ρs·A(N·V) renormalised by its
    // hemispherical mean 1 − ρs·Ā(m), so that light entering leaves whole and a
    // white surface under a white sky reflects 1 (Kelemen & Szirmay-Kalos
    // 2001's coupled diffuse term; docs/design/skin.md, "White furnace").
    float exit = (1.0 - reflected) / max(1.0 - params.x * albedos.y, 1e-3);
    // The transmitted light enters with the pre-scatter albedo, as the
    // irradiance does (x's own albedo for the far side's).
    vec3 through = vec3(0.0);
    if (TRANSMISSION) {
        through = (back_side ? lookup(translucent_back) : lookup(translucent_front))
                * pc.transmission * pow(albedo, vec3(pc.mix_pre));
        diffuse += through;
    }
    vec3 sss = diffuse * pow(albedo, vec3(1.0 - pc.mix_pre)) / PI * exit;
    vec3 spec = vec3(0.0);
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        vec3 l;
        vec3 e = light_irradiance(i, v_position, v_normal, n, v_uv, l);
        spec += e * ks_specular(n, l, v, light_lobe(i, params));
    }
    // The environment's share, occluded by what lies in the lobe about the
    // mirror direction (light/occlusion/lobe.rs; 1 without occlusion), not by
    // the diffuse's cosine-weighted open sky (docs/design/skin.md).
    vec3 r = reflect(-v, n);
    float visibility = OCCLUSION ? lobe_visibility(v_s012, v_s345, v_s678, r, n, params.y) : 1.0;
    // The blocked share sees the head's own skin, not the sky: taken as lit
    // like this point, its diffuse radiance (Jimenez et al. 2016's multi-bounce
    // assumption: the occluders look like the point they occlude).
    spec += reflected * mix(sss, prefiltered_radiance(r, params.y), visibility);
    if (pc.mode == 3u) {
        color = vec4(through * pow(albedo, vec3(1.0 - pc.mix_pre)) / PI * exit, 1.0);
        return;
    }
    color = vec4(pc.mode == 1u ? sss : pc.mode == 2u ? spec : sss + spec, 1.0);
}
