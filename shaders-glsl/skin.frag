#version 460
// Final skin shading (GPU Gems 3 §14.5; the paper's Fig. 2): the diffusion
// profile as Σ w_i · blur_i, each blur normalised by its coverage, times the
// post-scatter albedo^(1-mix); Lambert's 1/π turns irradiance into radiance.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
layout(binding = 1) uniform sampler2D albedo_tex;
layout(binding = 2) uniform sampler2D blur1;
layout(binding = 3) uniform sampler2D blur2;
layout(binding = 4) uniform sampler2D blur3;
layout(binding = 5) uniform sampler2D blur4;
layout(binding = 6) uniform sampler2D blur5;
layout(binding = 7) uniform sampler2D blur6;
layout(push_constant) uniform Push { vec4 weights[6]; float mix_pre; } pc;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 0) out vec4 color;

const float PI = 3.14159265358979;

vec3 level(sampler2D t, int i) {
    vec4 b = texture(t, v_uv);
    return pc.weights[i].rgb * (b.rgb / max(b.a, 1e-4));
}

void main() {
    vec3 diffuse = level(blur1, 0) + level(blur2, 1) + level(blur3, 2)
                 + level(blur4, 3) + level(blur5, 4) + level(blur6, 5);
    vec3 albedo = texture(albedo_tex, v_uv).rgb;
    color = vec4(diffuse * pow(albedo, vec3(1.0 - pc.mix_pre)) / PI, 1.0);
}
