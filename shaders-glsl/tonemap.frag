#version 460
// Exposure (EV stops) then the output transfer function (post/tonemap.rs), into 8-bit.
#extension GL_GOOGLE_include_directive : require
#include "color.glsl"
layout(binding = 0) uniform sampler2D hdr;
// gamma 0: the sRGB curve; else encoded = linear^(1/gamma).
layout(push_constant) uniform Push { float exposure; float gamma; } pc;
layout(location = 0) out vec4 color;

void main() {
    vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * exp2(pc.exposure);
    vec3 e = pc.gamma > 0.0 ? pow(clamp(c, 0.0, 1.0), vec3(1.0 / pc.gamma)) : linear_to_srgb(c);
    color = vec4(e, 1.0);
}
