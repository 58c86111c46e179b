#version 460
// Glow (post/glow.rs): the image plus its two blurred Gaussians, each weighted
// (× intensity) and read bilinearly from its mip level, texel centres at
// (i + ½)·2^k pixels; alpha (coverage) kept.
layout(binding = 0) uniform sampler2D hdr;
layout(binding = 1) uniform sampler2D glow1;
layout(binding = 2) uniform sampler2D glow2;
layout(push_constant) uniform Push { vec2 weights; vec2 scale; } pc;
layout(location = 0) out vec4 color;

void main() {
    vec2 p = gl_FragCoord.xy;
    vec4 c = texelFetch(hdr, ivec2(p), 0);
    vec3 g1 = textureLod(glow1, p / (pc.scale.x * vec2(textureSize(glow1, 0))), 0.0).rgb;
    vec3 g2 = textureLod(glow2, p / (pc.scale.y * vec2(textureSize(glow2, 0))), 0.0).rgb;
    color = vec4(c.rgb + pc.weights.x * g1 + pc.weights.y * g2, c.a);
}
