#version 460
// uv.vert plus the vertex's SH transfer, for the irradiance pass, and the light
// the skin reflects onto the vertex (light/interreflection.rs): the
// interreflected transfer applied to the environment's SH and to the explicit
// lights projected into SH here (a directional light of irradiance E from l is
// the radiance E·δ(ω − l), coefficients E·y_j(l); a point light's seen from
// the vertex), plus the environment's light through thin skin
// (light/transmission.rs; the lights' is the final pass's), zero without them.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 14
#include "transfer.glsl"
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 4) out vec3 v_t012;
layout(location = 5) out vec3 v_t345;
layout(location = 6) out vec3 v_t678;
layout(location = 7) out vec3 v_indirect;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    load_transfer(v_t012, v_t345, v_t678);
    vec3 L[9];
    for (int j = 0; j < 9; ++j) L[j] = lighting.sh[j].rgb;
    vec3 through = rgb_transfer_irradiance(TRANSMITTED, L);
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        vec3 l;
        float dist;
        vec3 e = light_incident(i, position, l, dist);
        float y[9];
        sh_basis(l, y);
        for (int j = 0; j < 9; ++j) L[j] += e * y[j];
    }
    v_indirect = OCCLUSION ? rgb_transfer_irradiance(INTERREFLECTED, L) + through : vec3(0.0);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
