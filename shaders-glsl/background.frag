#version 460
// The environment seen through the camera, behind the mesh. Alpha 0: the HDR
// image's alpha is the mesh's coverage (post/meter.rs meters by it).
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "envmap.glsl"
layout(binding = 1) uniform sampler2D env_tex;
layout(push_constant) uniform Push { vec2 size; } pc;
layout(location = 0) out vec4 color;

void main() {
    vec2 ndc = gl_FragCoord.xy / pc.size * 2.0 - 1.0;
    vec4 far = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 dir = far.xyz / far.w - frame.camera_pos.xyz;
    vec3 radiance = textureLod(env_tex, equirect_uv(env_dir(dir, frame.env.x)), 0.0).rgb;
    color = vec4(radiance * frame.env.y, 0.0);
}
