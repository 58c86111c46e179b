#version 460
// The debug views of the mesh (post/debug.rs): 0 linear depth, 1 the shading
// normal (world, 0.5·n + 0.5), 2 the albedo (linear), 3 the face regions.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "normal_map.glsl"
layout(binding = 1) uniform sampler2D albedo_tex;
layout(binding = 2) uniform sampler2D normal_tex;
layout(binding = 3) uniform sampler2D region_ids;   // red = id / 255, nearest
layout(push_constant) uniform Push { vec4 forward_near; float far; uint mode; } pc;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 0) out vec4 color;

// Tableau 10 (Tableau Software's default categorical palette, 2016), sRGB.
const vec3 REGION_COLORS[10] = vec3[](
    vec3(78, 121, 167), vec3(242, 142, 43), vec3(225, 87, 89), vec3(118, 183, 178),
    vec3(89, 161, 79), vec3(237, 201, 72), vec3(176, 122, 161), vec3(255, 157, 167),
    vec3(156, 117, 95), vec3(186, 176, 172));

void main() {
    vec3 dpdx = dFdx(v_position), dpdy = dFdy(v_position);
    vec3 c;
    if (pc.mode == 0u) {
        float z = dot(v_position - frame.camera_pos.xyz, pc.forward_near.xyz);
        c = vec3(clamp((pc.far - z) / (pc.far - pc.forward_near.w), 0.0, 1.0));
    } else if (pc.mode == 1u) {
        vec3 n = map_normal(normal_tex, v_uv, v_normal, v_tangent);
        if (seen_from_behind(v_normal, frame.camera_pos.xyz - v_position, dpdx, dpdy)) n = -n;
        c = 0.5 * n + 0.5;
    } else if (pc.mode == 2u) {
        c = texture(albedo_tex, v_uv).rgb;
    } else {
        int id = int(round(textureLod(region_ids, v_uv, 0.0).r * 255.0));
        c = id < 10 ? REGION_COLORS[id] / 255.0 : vec3(0.0);
    }
    color = vec4(c, 1.0);
}
