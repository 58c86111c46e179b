#version 460
// The environment prefiltered by the KS lobe for split-sum environment specular
// (Karis 2013, with the KS BRDF instead of GGX): at direction r and roughness m,
// the average of L(l) weighted by f_KS(l, v)·(n·l) with n = v = r. Beckmann
// importance sampling of the half vector, each sample read from the mip level
// whose texel matches its solid angle (filtered importance sampling, Colbert &
// Křivánek, GPU Gems 3 ch. 20). light/prefilter.rs; CPU reference there.
#extension GL_GOOGLE_include_directive : require
#include "envmap.glsl"
#include "env_specular.glsl"
#include "fresnel.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D env;
layout(binding = 1, rgba16f) writeonly uniform image2D prefiltered;
// The lobe's Schlick F0 (skin::specular::Lobe::schlick_f0; light/prefilter.rs sets it):
// fixed for a render, as the image this pass fills once.
layout(constant_id = 0) const float LOBE_F0 = 0.028;
const uint SAMPLES = 1024u;

// Van der Corput radical inverse in base 2 (Hammersley's second coordinate).
float radical_inverse(uint i) {
    return float(bitfieldReverse(i)) * 2.3283064365386963e-10;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= ENV_SPEC_W || p.y >= ENV_SPEC_H * ENV_SPEC_LEVELS) return;
    int level = p.y / ENV_SPEC_H;
    float m = ENV_SPEC_M0 + float(level) * ENV_SPEC_DM;
    vec3 r = equirect_dir((vec2(p.x, p.y - level * ENV_SPEC_H) + 0.5) / vec2(ENV_SPEC_W, ENV_SPEC_H));
    vec3 t = normalize(cross(abs(r.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), r));
    vec3 b = cross(r, t);
    vec2 size = vec2(textureSize(env, 0));
    // Solid angle of a level-0 texel on the equator; × sin θ elsewhere.
    float texel_sr = (2.0 * PI / size.x) * (PI / size.y);
    float max_lod = float(textureQueryLevels(env) - 1);
    vec3 acc = vec3(0.0);
    float total = 0.0;
    for (uint i = 0u; i < SAMPLES; ++i) {
        // Beckmann: tan²θh = −m² ln(1 − ξ), density D(h)(n·h) over the half vector.
        float tan2 = -m * m * log(1.0 - (float(i) + 0.5) / float(SAMPLES));
        float cos_h = inversesqrt(1.0 + tan2);
        float sin_h = sqrt(max(1.0 - cos_h * cos_h, 0.0));
        float phi = 2.0 * PI * radical_inverse(i);
        vec3 h = (t * cos(phi) + b * sin(phi)) * sin_h + r * cos_h;
        vec3 l = 2.0 * cos_h * h - r;
        float n_dot_l = dot(r, l);
        if (n_dot_l <= 0.0) continue;
        // pdf(l) = D(h)(n·h) / (4 v·h) = D(h)/4 with n = v; D normalised Beckmann.
        float d = exp(-tan2 / (m * m)) / (PI * m * m * cos_h * cos_h * cos_h * cos_h);
        float sample_sr = 4.0 / (float(SAMPLES) * d);
        float sin_theta = sqrt(max(1.0 - l.y * l.y, 1e-6));
        float lod = clamp(0.5 * log2(sample_sr / (texel_sr * sin_theta)) + 0.5, 0.0, max_lod);
        // f_KS·(n·l)/pdf = F(h·v)(n·l)/(n·h)² (see skin/specular.rs::specular_albedo).
        float w = fresnel_schlick(cos_h, LOBE_F0) * n_dot_l / (cos_h * cos_h);
        acc += w * textureLod(env, equirect_uv(l), lod).rgb;
        total += w;
    }
    imageStore(prefiltered, p, vec4(acc / max(total, 1e-20), 1.0));
}
