#version 460
// Exposure (EV, given or metered: post/meter.rs), the tone curve, the background
// where the mesh does not cover the image, then the output transfer function,
// into 8 bits. The formulas and their sources: post/tonemap.rs, whose CPU
// functions this mirrors.
#extension GL_GOOGLE_include_directive : require
#include "color.glsl"
layout(binding = 0) uniform sampler2D hdr;
// post/meter.rs: x = EV for the key, y = log-average luminance, z = pixels.
layout(std430, binding = 1) readonly buffer Metered { vec4 metered; };
// curve: 0 linear, 1 ACES (Narkowicz), 2 Khronos PBR Neutral.
// gamma 0: the sRGB curve; else encoded = linear^(1/gamma).
layout(push_constant) uniform Push {
    vec4 background;
    float exposure;
    float gamma;
    uint curve;
    uint use_metered;
} pc;
layout(location = 0) out vec4 color;

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 neutral(vec3 c) {
    const float start_compression = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(c.r, min(c.g, c.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    c -= offset;
    float peak = max(c.r, max(c.g, c.b));
    if (peak < start_compression) return c;
    float d = 1.0 - start_compression;
    float new_peak = 1.0 - d * d / (peak + d - start_compression);
    c *= new_peak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3(new_peak), g);
}

void main() {
    vec4 p = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0);
    float ev = pc.use_metered != 0u ? metered.x : pc.exposure;
    vec3 c = p.rgb * exp2(ev);
    c = pc.curve == 1u ? aces(c) : pc.curve == 2u ? neutral(c) : c;
    c += (1.0 - clamp(p.a, 0.0, 1.0)) * pc.background.rgb;
    vec3 e = pc.gamma > 0.0 ? pow(clamp(c, 0.0, 1.0), vec3(1.0 / pc.gamma)) : linear_to_srgb(c);
    color = vec4(e, 1.0);
}
