#version 460
// The lights' visibility in texture space (light/visibility.rs): for every
// light with an angular size, the fraction of its source that reaches the surface
// (percentage-closer soft shadows, common/lights.glsl); with HARD, for every
// other shadowed light, its 3×3 PCF (hard_shadow), which the irradiance pass
// reads texel for texel. Three lights per target, premultiplied by coverage
// (alpha 1 on the mesh, 0 in the gutter) so that the shading passes
// renormalise where bilinear taps reach past a chart's border.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#define SHADOW_ATLAS 1
#define SHADOW_DEPTH 2
#include "lights.glsl"
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 0) out vec4 visibility0;
layout(location = 1) out vec4 visibility1;
layout(location = 2) out vec4 visibility2;

layout(constant_id = 6) const bool HARD = false;

void main() {
    shading_dpdx = dFdx(v_position);
    shading_dpdy = dFdy(v_position);
    vec3 ng = normalize(v_normal);
    float v[9] = float[9](1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0);
    int lights = HARD ? SHADOWED_LIGHTS & ~SOFT_LIGHTS : SOFT_LIGHTS;
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        if ((lights & (1 << i)) == 0) continue;
        int slot = bitCount(lights & ((1 << i) - 1));
        if (HARD) {
            // What light_irradiance gives the shading passes, exactly.
            vec3 l;
            float dist;
            light_incident(i, v_position, l, dist);
            v[slot] = hard_shadow(i, v_position, v_normal, l, dist);
        } else {
            // Well past the terminator no normal map turns the surface to the light.
            v[slot] = dot(ng, frame.light_vec[i].xyz) < -0.5 ? 0.0 : soft_shadow(i, v_position, ng);
        }
    }
    visibility0 = vec4(v[0], v[1], v[2], 1.0);
    visibility1 = vec4(v[3], v[4], v[5], 1.0);
    visibility2 = vec4(v[6], v[7], v[8], 1.0);
}
