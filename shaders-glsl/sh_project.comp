#version 460
// SH projection of a lat-long environment, one workgroup per row: Σ L(ω)·y_i(ω)·dω
// with the exact texel solid angle (2π/W)(cos θ0 − cos θ1) (light/sh.rs::project).
#extension GL_GOOGLE_include_directive : require
#include "envmap.glsl"
#include "sh_basis.glsl"
layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2D env;
layout(std430, binding = 1) writeonly buffer Partials { float partials[]; };   // [row][27]
shared float sums[64 * 27];

void main() {
    ivec2 size = textureSize(env, 0);
    uint row = gl_WorkGroupID.x;
    uint lid = gl_LocalInvocationID.x;
    float v0 = float(row) / float(size.y), v1 = float(row + 1) / float(size.y);
    float d_omega = 2.0 * PI / float(size.x) * (cos(PI * v0) - cos(PI * v1));
    float theta = PI * (float(row) + 0.5) / float(size.y);
    float acc[27];
    for (int k = 0; k < 27; ++k) acc[k] = 0.0;
    for (uint x = lid; x < uint(size.x); x += 64u) {
        float phi = 2.0 * PI * ((float(x) + 0.5) / float(size.x) - 0.5);
        vec3 d = vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
        vec3 l = texelFetch(env, ivec2(x, row), 0).rgb;
        float b[9];
        sh_basis(d, b);
        for (int i = 0; i < 9; ++i) {
            acc[3 * i] += l.r * b[i];
            acc[3 * i + 1] += l.g * b[i];
            acc[3 * i + 2] += l.b * b[i];
        }
    }
    for (int k = 0; k < 27; ++k) sums[lid * 27u + uint(k)] = acc[k] * d_omega;
    barrier();
    for (uint s = 32u; s > 0u; s >>= 1) {
        if (lid < s) {
            for (uint k = 0u; k < 27u; ++k) sums[lid * 27u + k] += sums[(lid + s) * 27u + k];
        }
        barrier();
    }
    if (lid == 0u) {
        for (uint k = 0u; k < 27u; ++k) partials[row * 27u + k] = sums[k];
    }
}
