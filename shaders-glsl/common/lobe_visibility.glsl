// The environment specular's occlusion (light/occlusion/lobe.rs, the same in
// Rust): the vertex's SH of its visibility (below the horizon open), convolved
// with a von Mises–Fisher lobe about the mirror direction r and read at r, its
// blocked share divided by the lobe's share above the tangent plane.
// g_l: the vMF's Legendre coefficients, g_1 = coth κ − 1/κ and
// g_{l+1} = g_{l−1} − (2l+1)/κ·g_l (Fisher 1953); κ(m) = 0.5/m² + 1.6 matches
// the KS lobe's mean cosine about r at normal incidence (lobe.rs's test).
#include "sh_basis.glsl"

float lobe_visibility(vec3 s012, vec3 s345, vec3 s678, vec3 r, vec3 n, float m) {
    float k = 0.5 / max(m * m, 1e-6) + 1.6;
    float e = exp(-2.0 * k);
    float g1 = (1.0 + e) / (1.0 - e) - 1.0 / k;
    float g2 = max(1.0 - 3.0 * g1 / k, 0.0);
    float g3 = max(g1 - 5.0 * g2 / k, 0.0);
    float g4 = max(g2 - 7.0 * g3 / k, 0.0);
    float g5 = max(g3 - 9.0 * g4 / k, 0.0);
    float y[9];
    sh_basis(r, y);
    float whole = s012.x * y[0]
                + g1 * (s012.y * y[1] + s012.z * y[2] + s345.x * y[3])
                + g2 * (s345.y * y[4] + s345.z * y[5] + s678.x * y[6] + s678.y * y[7] + s678.z * y[8]);
    // The half-space's Legendre series (½, ¾, 0, −7/16, 0, 11/32) through the lobe.
    float t = clamp(dot(n, r), 0.0, 1.0);
    float p3 = 0.5 * t * (5.0 * t * t - 3.0);
    float p5 = t * (63.0 * t * t * t * t - 70.0 * t * t + 15.0) / 8.0;
    float above = clamp(0.5 + 0.75 * g1 * t - 7.0 / 16.0 * g3 * p3 + 11.0 / 32.0 * g5 * p5, 0.5, 1.0);
    return clamp(1.0 - (1.0 - whole) / above, 0.0, 1.0);
}
