#version 460
// SH projection of a lat-long environment, one workgroup per row: Σ L_texel · ∫_texel y_i dω,
// each basis function integrated exactly over the texel's cell θ0..θ1 × φ0..φ1 (the
// closed forms of light/sh.rs::texel_integrals, in their cancellation-free forms), not
// sampled at its centre: a constant map gives L00 alone at any size.
#extension GL_GOOGLE_include_directive : require
#include "envmap.glsl"
layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2D env;
layout(std430, binding = 1) writeonly buffer Partials { float partials[]; };   // [row][27]
shared float sums[64 * 27];

void main() {
    ivec2 size = textureSize(env, 0);
    uint row = gl_WorkGroupID.x;
    uint lid = gl_LocalInvocationID.x;
    // The row's θ integrals: ∫ sinθ, ∫ sin²θ, ∫ sinθcosθ, ∫ sin³θ, ∫ cos²θ sinθ, ∫ sin²θ cosθ.
    float t0 = PI * float(row) / float(size.y), t1 = PI * float(row + 1u) / float(size.y);
    float tm = 0.5 * (t0 + t1), th = 0.5 * (t1 - t0);
    float s0 = sin(t0), c0 = cos(t0), s1 = sin(t1), c1 = cos(t1);
    float a0 = 2.0 * sin(tm) * sin(th);
    float a1 = th - cos(2.0 * tm) * sin(2.0 * th) * 0.5;
    float ac = sin(2.0 * tm) * sin(2.0 * th) * 0.5;
    float acc = a0 * (c0 * c0 + c0 * c1 + c1 * c1) / 3.0;
    float a3 = a0 - acc;
    float asc = 2.0 * cos(tm) * sin(th) * (s1 * s1 + s1 * s0 + s0 * s0) / 3.0;
    // Every column is 2π/W wide: half width ph.
    float ph = PI / float(size.x);
    float sin_ph = sin(ph), sin_2ph = sin(2.0 * ph);
    float acc_k[27];
    for (int k = 0; k < 27; ++k) acc_k[k] = 0.0;
    for (uint x = lid; x < uint(size.x); x += 64u) {
        float pm = 2.0 * PI * ((float(x) + 0.5) / float(size.x) - 0.5);
        // The column's φ integrals: ∫ 1, ∫ sinφ, ∫ cosφ, ∫ sin²φ, ∫ cos²φ, ∫ sinφcosφ.
        float p0 = 2.0 * ph;
        float ps = 2.0 * sin(pm) * sin_ph;
        float pc = 2.0 * cos(pm) * sin_ph;
        float half_c = cos(2.0 * pm) * sin_2ph * 0.5;
        float pss = ph - half_c, pcc = ph + half_c;
        float psc = sin(2.0 * pm) * sin_2ph * 0.5;
        // d = (sinθ sinφ, cosθ, −sinθ cosφ), dω = sinθ dθ dφ.
        float one = a0 * p0;
        float b[9];
        b[0] = 0.282095 * one;
        b[1] = 0.488603 * (ac * p0);
        b[2] = 0.488603 * (-a1 * pc);
        b[3] = 0.488603 * (a1 * ps);
        b[4] = 1.092548 * (asc * ps);
        b[5] = 1.092548 * (-asc * pc);
        b[6] = 0.315392 * (3.0 * a3 * pcc - one);
        b[7] = 1.092548 * (-a3 * psc);
        b[8] = 0.546274 * (a3 * pss - acc * p0);
        vec3 l = texelFetch(env, ivec2(x, row), 0).rgb;
        for (int i = 0; i < 9; ++i) {
            acc_k[3 * i] += l.r * b[i];
            acc_k[3 * i + 1] += l.g * b[i];
            acc_k[3 * i + 2] += l.b * b[i];
        }
    }
    for (int k = 0; k < 27; ++k) sums[lid * 27u + uint(k)] = acc_k[k];
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
