#version 460
// Exposure (EV stops) then the sRGB transfer function, into 8-bit.
#extension GL_GOOGLE_include_directive : require
#include "color.glsl"
layout(binding = 0) uniform sampler2D hdr;
layout(push_constant) uniform Push { float exposure; } pc;
layout(location = 0) out vec4 color;

void main() {
    vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * exp2(pc.exposure);
    color = vec4(linear_to_srgb(c), 1.0);
}
