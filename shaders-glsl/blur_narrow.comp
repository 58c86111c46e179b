#version 460
// One Gaussian of the skin chain narrower than a texel (skin/chain.rs,
// ONE_PASS_SIGMA_TEXELS), both directions in one pass, source and destination of
// one size (issue 24). Its covariance in source texels is σ²·U·Uᵀ, U = [[r, b],
// [0, g]] the stretch map's factor (stretch.frag: the U pass steps (r, 0) and the
// V pass (b, g) texels per mm, so this is the two passes' covariance). A Gaussian
// this narrow reaches the 3×3 neighbourhood only, and is read as four bilinear
// taps in two pairs ±d1, ±d2 (weights w1/2, w2/2) whose moments are its own: a
// bilinear tap at offset o ∈ [0, 1] from a texel centre puts 1 − o on it and o
// on the next, so its second moment is o (not o²) along each axis and ox·oy
// across. Pairs (ox, ±oy) with ox = Σuu, oy = Σvv give the variances, per axis
// the tent m/2, 1 − m, m/2, and their weights (1 ± c)/2 a cross moment c·ox·oy.
// A larger cross moment (narrow and sheared: |Σuv| up to min(Σuu, Σvv), what
// any 3×3 stencil of positive weights holds) puts one pair on the diagonal at
// (Σuv/Σvv, Σuv/Σuu) with weight Σuu·Σvv/Σuv and the rest on the centre. The
// variance is exact, not σ² plus bilinear filtering's share as with the
// separable taps.
// Images are coverage-premultiplied, as in blur.comp.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1) uniform sampler2D stretch;
layout(binding = 2, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { float sigma_mm; } pc;

// The offset of a bilinear tap whose second moment about the texel centre is m:
// at o = n + f, (1 − f)·n² + f·(n + 1)² = m; under one texel o = m. (Above a
// texel, where the stretch is far above the mean, the variance stays exact and
// the taps leave the 3×3 stencil's centre row and column.)
float tap_offset(float m) {
    float n = floor(sqrt(m));
    return n + (m - n * n) / (2.0 * n + 1.0);
}

void main() {
    ivec2 size = imageSize(dst);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec2 texel = 1.0 / vec2(size);
    vec2 uv = (vec2(p) + 0.5) * texel;
    // (r, g, b) in texels of this size per mm; in the gutter, one texel per mm.
    vec4 st = textureLod(stretch, uv, 0.0);
    vec2 scale = vec2(size) / vec2(textureSize(stretch, 0));
    vec3 s = st.a > 1e-4 ? st.rgb / st.a * scale.xyx : vec3(1.0, 1.0, 0.0);
    float v = pc.sigma_mm * pc.sigma_mm;
    float x = v * (s.x * s.x + s.z * s.z), y = v * s.y * s.y, xy = v * s.z * s.y;
    vec2 o = vec2(tap_offset(x), tap_offset(y));
    float a = min(abs(xy), min(min(x, y), 1.0));
    bool paired = a <= o.x * o.y;
    vec2 d1 = paired ? o : vec2(a / y, a / x);
    vec2 d2 = paired ? o : vec2(0.0);
    float w1 = paired ? 0.5 + 0.5 * a / max(o.x * o.y, 1e-12) : x * y / a;
    // d1 on the diagonal of Σuv's sign, d2 across it.
    float sgn = xy < 0.0 ? -1.0 : 1.0;
    d1 *= vec2(1.0, sgn) * texel;
    d2 *= vec2(1.0, -sgn) * texel;
    vec4 along = textureLod(src, uv + d1, 0.0) + textureLod(src, uv - d1, 0.0);
    vec4 across = textureLod(src, uv + d2, 0.0) + textureLod(src, uv - d2, 0.0);
    imageStore(dst, p, 0.5 * (w1 * along + (1.0 - w1) * across));
}
