#version 460
// Writes src * scale + bias for pixels left of split_x; optionally sRGB-encodes.
#extension GL_GOOGLE_include_directive : require
#include "color.glsl"
layout(binding = 0) uniform sampler2D src;
layout(push_constant) uniform Push { float scale; float bias; float split_x; uint encode_srgb; } pc;
layout(location = 0) out vec4 color;

void main() {
    if (gl_FragCoord.x >= pc.split_x) discard;
    vec4 c = texelFetch(src, ivec2(gl_FragCoord.xy), 0) * pc.scale + pc.bias;
    color = pc.encode_srgb != 0u ? vec4(linear_to_srgb(c.rgb), 1.0) : c;
}
